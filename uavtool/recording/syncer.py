"""`Syncer`: fsyncs one open file on a background thread, so writers never wait for the disk.

The caller writes (and flushes) its data to the OS itself, which is all a SIGKILL needs, then
calls `request`; the thread fsyncs everything written so far, against a power cut. Requests
that arrive while an fsync runs are served together by the next one, so a slow disk costs
fewer fsyncs rather than a longer queue. The first failed fsync stops the thread and is kept
in `failure` for the owner to report: after a failed fsync Linux may drop the dirty pages and
report success next time, so retrying would hide lost data.
"""

from __future__ import annotations

import os
import threading


class Syncer:
    """Background fsync of file descriptor ``fd``; ``name`` labels the thread."""

    def __init__(self, fd: int, name: str) -> None:
        self._fd = fd
        self._cond = threading.Condition(threading.Lock())
        self._requested = 0  # requests made so far
        self._synced = 0  # requests covered by a finished fsync
        self._stopping = False
        self._ended = False  # the thread has returned (or died)
        self.failure: OSError | None = None  # set once, by the thread
        self._thread = threading.Thread(target=self._run, name=f"fsync {name}", daemon=True)
        self._thread.start()

    def request(self) -> None:
        """Ask for an fsync of everything written so far; returns at once."""
        with self._cond:
            self._requested += 1
            self._cond.notify_all()

    def wait(self) -> None:
        """Block until every request made before this call is on disk or an fsync failed."""
        with self._cond:
            target = self._requested
            while self._synced < target and self.failure is None and not self._ended:
                self._cond.wait()

    def stop(self) -> None:
        """Serve the outstanding requests, then end the thread. Idempotent."""
        with self._cond:
            self._stopping = True
            self._cond.notify_all()
        self._thread.join()

    def _run(self) -> None:
        try:
            self._serve()
        finally:  # whatever ends the thread, nobody may keep waiting for it
            with self._cond:
                self._ended = True
                self._cond.notify_all()

    def _serve(self) -> None:
        while True:
            with self._cond:
                while self._synced == self._requested and not self._stopping:
                    self._cond.wait()
                if self._synced == self._requested:  # stopping, nothing left
                    return
                target = self._requested
            try:
                os.fsync(self._fd)
            except OSError as exc:
                with self._cond:
                    self.failure = exc
                    self._cond.notify_all()
                return
            with self._cond:
                self._synced = target
                self._cond.notify_all()
