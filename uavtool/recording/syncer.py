"""`Syncer`: writes a recording's closed chunks to its file on a background thread, and with
``fsync`` puts them on disk, so writers never wait for compression or the disk.

The caller hands over jobs (compress and write a chunk, write a metadata record) in file
order; the thread runs them in that order, each handing its bytes to the OS (all a SIGKILL
needs), then, with ``fsync``, fsyncs everything written so far, against a power cut. Jobs
that arrive while an fsync runs, or within `SYNC_INTERVAL_S` of the last one, are written
and synced together by the next one, so a slow disk or a fast flight costs fewer fsyncs
rather than a longer queue. zstd and the file's writes release the
GIL: a chunk is compressed while the flight goes on.

The first failed job or fsync stops the thread and is kept in `failure` (with `problem`:
what failed) for the owner to report; later jobs are not run. After a failed fsync Linux
may drop the dirty pages and report success next time, so retrying would hide lost data.
"""

from __future__ import annotations

import os
import threading
import time
from collections import deque
from collections.abc import Callable

WRITE_FAILED = "cannot write"
SYNC_FAILED = "cannot sync to disk"
BACKLOG = 8
"""Jobs (chunks) that may wait for the thread before `Syncer.submit` waits too."""
SYNC_INTERVAL_S = 0.1
"""Least wall time between two fsyncs, unless someone waits for one (`Syncer.wait`, the
owner's close): a lockstep flight closes a chunk every few milliseconds, and an fsync each
time cost it about 3 % of its wall time for nothing a power cut would notice; a real-time
flight closes one a second and is synced as before."""


class Syncer:
    """Background writes (and with ``fsync`` fsyncs) of file descriptor ``fd``; ``name``
    labels the thread."""

    def __init__(self, fd: int, name: str, *, fsync: bool = True) -> None:
        self._fd = fd
        self._fsync = fsync
        self._cond = threading.Condition(threading.Lock())
        self._jobs: deque[Callable[[], None]] = deque()
        self._submitted = 0  # jobs handed over so far
        self._done = 0  # jobs run (and with fsync, synced: see _served)
        self._synced = 0  # jobs covered by a finished fsync
        self._last_sync = -SYNC_INTERVAL_S  # time.monotonic() of the last fsync
        self._waiting = 0  # callers of wait(): they get their fsync at once
        self._stopping = False
        self._final_sync = True  # whether stopping still syncs the last jobs
        self._ended = False  # the thread has returned (or died)
        self.failure: OSError | None = None  # set once, by the thread
        self.problem = ""  # WRITE_FAILED or SYNC_FAILED, with `failure`
        self._thread = threading.Thread(target=self._run, name=f"recording {name}", daemon=True)
        self._thread.start()

    def submit(self, job: Callable[[], None]) -> None:
        """Run ``job`` after every job handed over before it. Returns at once unless
        `BACKLOG` jobs already wait: then it first waits for the thread (which a writer
        holding the GIL can starve), so a crash loses no more than those."""
        with self._cond:
            while len(self._jobs) >= BACKLOG and self.failure is None and not self._ended:
                self._cond.wait()
            self._jobs.append(job)
            self._submitted += 1
            self._cond.notify_all()

    def wait(self) -> None:
        """Block until every job handed over before this call has run and (with fsync) is
        on disk, or a job or an fsync failed."""
        with self._cond:
            target = self._submitted
            self._waiting += 1
            self._cond.notify_all()
            try:
                while self._served() < target and self.failure is None and not self._ended:
                    self._cond.wait()
            finally:
                self._waiting -= 1

    def stop(self, *, sync: bool = True) -> None:
        """Run the outstanding jobs and (with fsync, unless ``sync`` is false: the owner
        fsyncs the file itself next) sync them, then end the thread. Idempotent."""
        with self._cond:
            self._stopping = True
            self._final_sync = self._final_sync and sync
            self._cond.notify_all()
        self._thread.join()

    def _served(self) -> int:
        return self._synced if self._fsync else self._done

    def _run(self) -> None:
        try:
            self._serve()
        finally:  # whatever ends the thread, nobody may keep waiting for it
            with self._cond:
                self._ended = True
                self._cond.notify_all()

    def _fail(self, problem: str, exc: OSError) -> None:
        with self._cond:
            self.failure, self.problem = exc, problem
            self._cond.notify_all()

    def _serve(self) -> None:
        while True:
            with self._cond:
                while not self._jobs and self._synced == self._done and not self._stopping:
                    self._cond.wait()
                job = self._jobs.popleft() if self._jobs else None
                if job is not None:
                    self._cond.notify_all()  # a writer waiting for room in the backlog
                if job is None and (
                    self._synced == self._done or (self._stopping and not self._final_sync)
                ):  # stopping, nothing left to do
                    return
                if job is None and not (self._stopping or self._waiting):
                    pause = self._last_sync + SYNC_INTERVAL_S - time.monotonic()
                    if pause > 0:  # too soon: more jobs may come to share the next fsync
                        self._cond.wait(pause)
                        continue
            if job is not None:
                try:
                    job()
                except OSError as exc:
                    self._fail(WRITE_FAILED, exc)
                    return
                with self._cond:
                    self._done += 1
                    if not self._fsync:
                        self._synced = self._done
                    self._cond.notify_all()
                continue
            target = self._done  # every job written: one fsync covers them all
            self._last_sync = time.monotonic()
            try:
                os.fsync(self._fd)
            except OSError as exc:
                self._fail(SYNC_FAILED, exc)
                return
            with self._cond:
                self._synced = target
                self._cond.notify_all()
