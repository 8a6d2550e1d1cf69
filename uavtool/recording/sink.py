"""`RecordingSink`: where a recording's bytes go, and how durably.

It owns the file, the `McapEncoder` and the chunk policy: the open chunk is closed, written
and flushed to the OS once it spans ``interval_ns`` of log time or holds ``budget_bytes``,
so a SIGKILL loses at most that chunk. With ``fsync`` a `Syncer` then puts each closed
chunk on disk in the background, against a power cut, without making the writer wait.

The first failed write or fsync breaks the sink for good: every later call raises
`RecordingError` naming the file and the OS error, and so does `close` (which still
releases the file), so a failure is never mistaken for a whole recording.
"""

from __future__ import annotations

import contextlib
import os
import weakref
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import NoReturn

from uavtool.recording.encoder import McapEncoder
from uavtool.recording.errors import RecordingError, create_file
from uavtool.recording.syncer import Syncer


class RecordingSink:
    """An MCAP file being written at ``path``; its header and ``metadata`` records are
    written (and handed to the OS) at once. Not thread-safe: the writer serializes calls.
    Raises `RecordingError` if the file cannot be created or written."""

    def __init__(
        self,
        path: Path,
        *,
        library: str,
        metadata: Iterable[tuple[str, Mapping[str, str]]],
        interval_ns: int,
        budget_bytes: int,
        fsync: bool,
    ) -> None:
        self.path = path
        self._interval_ns = interval_ns
        self._budget = budget_bytes
        self._fsync = fsync
        self._chunk_start_ns: int | None = None  # log time of the open chunk's first message
        self._error: OSError | None = None  # the failed write or fsync, once there is one
        self._problem = ""
        self._closed = False
        self._syncer: Syncer | None = None
        self._file = create_file(path)
        try:
            self._encoder = McapEncoder(self._file, library=library)
            for name, pairs in metadata:
                self._encoder.add_metadata(name, pairs)
        except OSError as exc:
            self._closed = True
            with contextlib.suppress(OSError):  # the buffered bytes fail again
                self._file.close()
            raise RecordingError(path, f"cannot write: {exc.strerror or exc}") from exc
        if fsync:
            self._syncer = Syncer(self._file.fileno(), path.name)
            # A sink dropped without close() still ends its thread (the file is still open
            # when this runs); close() runs it first, and it runs once.
            self._stop_syncer = weakref.finalize(self, self._syncer.stop)

    def check(self) -> None:
        """Raise `RecordingError` if a write or fsync has failed."""
        self._take_sync_failure()
        if self._error is not None:
            raise RecordingError(self.path, self._problem) from self._error

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        return self._encoder.register_schema(name, encoding, data)  # no I/O: in the open chunk

    def register_channel(
        self, topic: str, encoding: str, schema_id: int, metadata: Mapping[str, str]
    ) -> int:
        return self._encoder.register_channel(topic, encoding, schema_id, metadata)

    def add_metadata(self, name: str, pairs: Mapping[str, str]) -> None:
        self.check()
        try:
            self._encoder.add_metadata(name, pairs)
        except OSError as exc:
            self._fail("cannot write", exc)

    def add(
        self, channel_id: int, sequence: int, log_time_ns: int, publish_time_ns: int, data: bytes
    ) -> None:
        """Add a message; close the chunk if it now spans the interval or fills the budget.
        `struct.error` (times or sequence out of range) leaves everything unchanged."""
        syncer = self._syncer
        if self._error is not None or (syncer is not None and syncer.failure is not None):
            self.check()
        size = self._encoder.add_message(channel_id, sequence, log_time_ns, publish_time_ns, data)
        start_ns = self._chunk_start_ns
        if start_ns is None:
            self._chunk_start_ns = start_ns = log_time_ns
        if log_time_ns - start_ns >= self._interval_ns or size >= self._budget:
            self.close_chunk()

    def close_chunk(self) -> None:
        """Write the open chunk to the OS now and ask for an fsync (returns at once)."""
        self.check()
        try:
            self._encoder.close_chunk()
        except OSError as exc:
            self._fail("cannot write", exc)
        self._chunk_start_ns = None
        if self._syncer is not None:
            self._syncer.request()

    def wait_synced(self) -> None:
        """Block until every chunk closed so far is on disk (no-op without fsync)."""
        if self._syncer is not None:
            self._syncer.wait()
        self.check()

    def close(self) -> None:
        """Write the summary, wait for every fsync, fsync the end and close the file.
        Idempotent; raises `RecordingError` (after releasing the file) if anything failed."""
        if self._closed:
            return
        self._closed = True
        self._take_sync_failure()
        if self._error is None:
            try:
                self._encoder.finish()
            except OSError as exc:
                self._record("cannot write", exc)
        if self._syncer is not None:
            self._stop_syncer()
            self._take_sync_failure()
        if self._fsync and self._error is None:
            try:
                os.fsync(self._file.fileno())
            except OSError as exc:
                self._record("cannot sync to disk", exc)
        try:
            self._file.close()
        except OSError as exc:  # a failed recording's buffered bytes fail again
            if self._error is None:
                self._record("cannot write", exc)
        self.check()

    def _take_sync_failure(self) -> None:
        syncer = self._syncer
        if self._error is None and syncer is not None and syncer.failure is not None:
            self._record("cannot sync to disk", syncer.failure)

    def _record(self, what: str, exc: OSError) -> None:
        self._error = exc
        self._problem = f"{what}: {exc.strerror or exc}; the recording stopped there"

    def _fail(self, what: str, exc: OSError) -> NoReturn:
        self._record(what, exc)
        raise RecordingError(self.path, self._problem) from exc
