"""`RecordingSink`: where a recording's bytes go, and how durably.

It owns the file, the `McapEncoder` and the chunk policy: the open chunk is closed once it
spans ``interval_ns`` of log time or holds ``budget_bytes``; a `Syncer` thread then
compresses it, writes and flushes it to the OS at once, so a SIGKILL loses about that chunk
at most, and with ``fsync`` puts it on disk, against a power cut, without making the writer
wait. Metadata records after the start go through the same thread, in order.

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
from typing import BinaryIO

from uavtool.recording.encoder import McapEncoder
from uavtool.recording.errors import RecordingError, create_file
from uavtool.recording.syncer import Syncer


class RecordingSink:
    """An MCAP file being written at ``path``; its header and ``metadata`` records are
    written (and handed to the OS) at once; ``file``: ``path`` already open (it is created
    otherwise). Not thread-safe: the writer serializes calls. Raises `RecordingError` if the
    file cannot be created or written."""

    def __init__(
        self,
        path: Path,
        *,
        library: str,
        metadata: Iterable[tuple[str, Mapping[str, str]]],
        interval_ns: int,
        budget_bytes: int,
        fsync: bool,
        file: BinaryIO | None = None,
    ) -> None:
        self.path = path
        self._interval_ns = interval_ns
        self._budget = budget_bytes
        self._fsync = fsync
        self._chunk_start_ns: int | None = None  # log time of the open chunk's first message
        self._error: OSError | None = None  # the failed write or fsync, once there is one
        self._problem = ""
        self._closed = False
        self._file = create_file(path) if file is None else file
        try:
            self._encoder = McapEncoder(self._file, library=library)
            for name, pairs in metadata:
                self._encoder.add_metadata(name, pairs)
        except OSError as exc:
            self._closed = True
            with contextlib.suppress(OSError):  # the buffered bytes fail again
                self._file.close()
            raise RecordingError(path, f"cannot write: {exc.strerror or exc}") from exc
        self._syncer = Syncer(self._file.fileno(), path.name, fsync=fsync)
        # A sink dropped without close() still ends its thread (the file is still open when
        # this runs); close() runs it first, and it runs once.
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
        """Write a metadata record after every chunk closed so far (on the thread)."""
        self.check()
        encoder, record = self._encoder, dict(pairs)
        self._syncer.submit(lambda: encoder.add_metadata(name, record))

    def add(
        self, channel_id: int, sequence: int, log_time_ns: int, publish_time_ns: int, data: bytes
    ) -> None:
        """Add a message; close the chunk if it now spans the interval or fills the budget.
        `struct.error` (times or sequence out of range) leaves everything unchanged."""
        if self._error is not None or self._syncer.failure is not None:
            self.check()
        size = self._encoder.add_message(channel_id, sequence, log_time_ns, publish_time_ns, data)
        start_ns = self._chunk_start_ns
        if start_ns is None:
            self._chunk_start_ns = start_ns = log_time_ns
        if log_time_ns - start_ns >= self._interval_ns or size >= self._budget:
            self.close_chunk()

    def close_chunk(self) -> None:
        """Hand the open chunk to the thread, which writes it to the OS (and with fsync
        syncs it) at once; returns at once."""
        self.check()
        chunk = self._encoder.take_chunk()
        self._chunk_start_ns = None
        if chunk is not None:
            write = self._encoder.write_chunk
            self._syncer.submit(lambda: write(chunk))

    def wait_synced(self) -> None:
        """Block until every chunk closed so far is written and (with fsync) on disk."""
        self._syncer.wait()
        self.check()

    def close(self) -> None:
        """Let the thread write what it holds, write the last chunk and the summary, fsync
        the whole file and close it. Idempotent; raises `RecordingError` (after releasing
        the file) if anything failed."""
        if self._closed:
            return
        self._closed = True
        # every job run (not synced: the fsync below covers them): from here on this
        # thread alone writes
        self._stop_syncer.detach()
        self._syncer.stop(sync=False)
        self._take_sync_failure()
        if self._error is None:
            try:
                self._encoder.finish()
            except OSError as exc:
                self._record("cannot write", exc)
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
        if self._error is None and syncer.failure is not None:
            self._record(syncer.problem, syncer.failure)

    def _record(self, what: str, exc: OSError) -> None:
        self._error = exc
        self._problem = f"{what}: {exc.strerror or exc}; the recording stopped there"
