"""`ProcessWriter`: a `RecordingWriter` in a process of its own, off the flight's path.

A lockstep flight runs as fast as one core allows, and Python's own cost per message (an MCAP
record of each frame, its JSON view, the Protobuf of every Foxglove value, a photo's PNG)
took a third of it. The flight's thread now only checks each call and appends it, as a tuple
of what it already holds (a time, the value's fields, a JSON template and its numbers), to a
batch (a MAVLink frame, the most frequent call by far, goes to columns of their own: one
string of their bytes, not a tuple each; a photo's pixels go down the pipe beside the
pickle, not copied into it); every `BATCH_NS` of log time (or `BATCH_CALLS` calls) the batch is
pickled down a pipe to a child process, which makes the very calls on a `RecordingWriter`
(decoding each frame again for its JSON view, encoding each value), so the file is the same,
byte for byte, as one written in the flight's process. The flight's process never imports
Protobuf.

What is kept:

- **Errors where they were.** Misuse (a time <= 0, an unknown topic, a payload that is not
  JSON) raises `ValueError` at the call, as `RecordingWriter` does. A failure of the writer
  (the disk full, its process gone) raises `RecordingError` at a later call or at `close`,
  and from then on at every call.
- **A crash loses little.** If the flight's process dies (a SIGKILL, a crash), the child
  reads what was sent up to there, writes it out and stops, leaving the file unfinished:
  only the batch not yet sent is lost, at most `BATCH_NS` of log time. Ctrl-C does not reach
  the child (a session of its own): the flight's process decides, as before, what to write
  last and when to close.
- **Back pressure.** The child reads the pipe in a thread of its own, so a photo it is
  compressing never keeps the flight waiting on a full pipe (it did: ~60 ms a flight); what
  it has read and not yet written is held to `process_child.BACKLOG_BYTES`, and a flight
  that outruns its writer by more waits for it. That thread looks at the pipe every
  millisecond or so (`process_child.POLL_S`) instead of waiting in ``read``: a waiting
  reader is woken by every batch, at the flight's cost.

The child is a fresh interpreter (`subprocess`, never a fork: the flight may run threads,
and in a Dask worker it is a daemon) with the parent's ``sys.path``; it imports the writer,
pymavlink's dialect and Foxglove's schemas (~0.1 s of CPU on the other core while the flight
starts), and neither numpy nor OpenCV nor trimesh: `uavtool.png` makes the frames' PNGs and
`uavtool.glb` the model's GLB in plain Python.
"""

from __future__ import annotations

import contextlib
import fcntl
import itertools
import json
import os
import pickle
import struct
import subprocess
import sys
import threading
import weakref
from array import array
from collections.abc import Callable, Mapping
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, BinaryIO, NoReturn

from uavtool.recording.errors import RecordingError, create_file
from uavtool.recording.protocol import check_metadata, check_topic
from uavtool.recording.schemas import DEFAULT_DIALECT, dialect_module, dumps
from uavtool.recording.topics import FIX, POSE
from uavtool.recording.values import (
    FOXGLOVE_TYPES,
    CompressedImage,
    Direction,
    LocationFix,
    PosesInFrame,
)

if TYPE_CHECKING:
    from uavtool.geo import GeoPoint
    from uavtool.recording.foxglove import FoxgloveValue

BATCH_NS = 1_000_000_000
"""Log time a batch may span before it is sent: what a crash of the flight may lose. Each
send wakes the child on another core, about 50 us in a virtual machine: a lockstep flight
sends ~230 batches, not ~900 as it would every quarter second."""
BATCH_CALLS = 2048
"""Calls a batch may hold before it is sent."""
PIPE_BYTES = 1 << 20
_HEADER = struct.Struct("<QI")  # each value on the pipe: its pickle's size, its buffers' count

# the calls, as the first item of each tuple in a batch (most frequent first)
(
    _MAV_IN,
    _MAV_OUT,
    _MAV_PUBLISHED_IN,
    _MAV_PUBLISHED_OUT,
    _VEHICLE,
    _ORIGIN,
    _JSON_FORMAT,
    _JSON,
    _PROTO_TOPIC,
    _JSON_TOPIC,
    _METADATA,
    _FLUSH,
    _CLOSE,
    _ENCODE,
    _ENCODE_RAW,
) = range(15)
_END_NS = 1 << 64
_Batch = tuple[list[tuple[Any, ...]], "array[int]", bytes, "array[int]", bytes, bytes]
"""What a batch is on the pipe: its calls other than tapped frames, how many frames come
before each, then the frames: their bytes joined, their sizes, directions and times."""
_CHILD = (
    "import sys, json; sys.path[:] = json.loads(sys.argv[1]); "
    "from uavtool.recording.process_child import serve; serve()"
)


def _check_time(t: Any, what: str = "log_time_ns") -> None:
    if type(t) is not int or not 0 < t < _END_NS:
        raise ValueError(f"{what} must be a positive int that fits 64 bits, got {t!r}")


def _check_times(log_time_ns: Any, publish_time_ns: Any) -> None:
    _check_time(log_time_ns)
    if publish_time_ns is not None:
        _check_time(publish_time_ns, "publish_time_ns")


class ProcessWriter:
    """`RecordingWriter`'s writes, made by a child process (the module docstring says how).
    Arguments as `RecordingWriter`'s; the file is created here, so a path that cannot be
    written raises `RecordingError` at once. Use as a context manager; safe to share between
    threads."""

    def __init__(
        self,
        path: str | Path,
        *,
        metadata: Mapping[str, Mapping[str, str]] | None = None,
        dialect: str = DEFAULT_DIALECT,
        chunk_interval_ns: int = 1_000_000_000,
        chunk_bytes: int = 1 << 20,
        fsync: bool = True,
    ) -> None:
        dialect_module(dialect)  # ValueError before a file exists, as RecordingWriter
        for name, record in (metadata or {}).items():
            check_metadata(name, record)
        self.dialect = dialect
        self.path = Path(path)
        self._lock = threading.Lock()
        self._batch: list[tuple[Any, ...]] = []
        # the batch's MAVLink frames apart, in columns (one pickled string of them all, not
        # a tuple each: a flight taps ~14,000), and where each call of the batch falls among
        # them (how many frames come before it)
        self._at = array("I")
        self._frames: list[bytes] = []
        self._frame_ops = bytearray()
        self._frame_times = array("Q")
        self._ship_at = 0  # log time from which the next call sends the batch
        # framed batches not yet in the pipe (Ctrl-C mid-write), as views: never copied
        self._pending: list[memoryview] = []
        self._json_topics: set[str] = set()
        self._topic_kind: dict[str, Any] = {}  # topic -> value type or JSON schema name
        self._protobuf_topics: set[str] = set()  # topics whose schema the child was sent
        self._vehicle = False  # write_vehicle was called
        self._origin: GeoPoint | None = None  # the origin of write_vehicle's last call
        self._failure: RecordingError | None = None
        self._closed = False
        self._message_count = 0
        file = create_file(self.path)
        wake, self._wake = os.pipe()  # see `process_child.POLL_S`
        os.set_blocking(self._wake, False)
        try:
            self._proc = _spawn(file, wake)
            init = (
                str(self.path),
                file.fileno(),
                wake,
                {k: dict(v) for k, v in (metadata or {}).items()},
                dialect,
                chunk_interval_ns,
                chunk_bytes,
                fsync,
            )
        except BaseException:
            os.close(self._wake)
            raise
        finally:
            file.close()  # the child has its own descriptors
            os.close(wake)
        assert self._proc.stdin is not None
        assert self._proc.stdout is not None
        self._out = self._proc.stdin.fileno()
        self._replies = self._proc.stdout
        # dropped without close(): the child still ends (and keeps what it was sent)
        self._finalizer = weakref.finalize(self, _abandon, self._proc, self._wake)
        self._send(init)

    # --- lifecycle ---------------------------------------------------------------------------

    def __enter__(self) -> ProcessWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        try:
            self.close()
        except RecordingError:
            if not (isinstance(exc, RecordingError) and exc.path == str(self.path)):
                raise

    @property
    def message_count(self) -> int:
        """Messages in the file: known once it is closed (0 before)."""
        return self._message_count

    def flush(self) -> None:
        """Send what is batched and wait until the child has closed its chunk and put it on
        disk (`RecordingWriter.flush`)."""
        with self._lock:
            self._check_open()
            self._add((_FLUSH,))
            self._ship(0)
            self._wake_child()
            self._reply()

    def hand_off(self) -> None:
        """Send what is batched now, without waiting for the child: it writes it while the
        flight's process does other work (a flight's evaluation) before `close`."""
        with self._lock:
            self._check_open()
            if self._batch or self._frames:
                self._ship(0)

    def close(self) -> None:
        """Send the rest, let the child write the summary, fsync and close the file, and wait
        for it. Idempotent; raises `RecordingError` if anything failed (the file is then not
        whole)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                if self._failure is None:
                    self._add((_CLOSE,))
                    self._ship(0)
                    self._wake_child()
                    reply = self._reply()
                    self._message_count = int(reply[1])
                    # the file is whole and on disk; the child only exits now (~3 ms of
                    # tearing down a process): reaped by a thread, not waited for
                    self._finalizer.detach()
                    _release(self._proc, self._wake, wait=False)
            finally:
                self._finalizer()
            if self._failure is not None:
                raise self._failure

    # --- metadata and channels ---------------------------------------------------------------

    def add_metadata(self, name: str, record: Mapping[str, str]) -> None:
        check_metadata(name, record)
        with self._lock:
            self._check_open()
            self._add((_METADATA, name, dict(record)))
            self._ship(0)

    def add_json_topic(self, topic: str, *, schema_name: str, schema: Mapping[str, Any]) -> None:
        check_topic(topic)
        with self._lock:
            self._check_open()
            known = self._topic_kind.get(topic)
            if known is not None:
                if known != schema_name:
                    raise ValueError(f"topic {topic!r} already carries {known!r}")
                return
            self._topic_kind[topic] = schema_name
            self._json_topics.add(topic)
            self._add((_JSON_TOPIC, topic, schema_name, json.loads(dumps(schema))))

    # --- writes ------------------------------------------------------------------------------

    def write_json(
        self,
        topic: str,
        payload: Mapping[str, Any],
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        try:
            data = dumps(payload)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"topic {topic!r}: payload is not JSON: {exc}") from exc
        self.write_json_bytes(topic, data, log_time_ns=log_time_ns, publish_time_ns=publish_time_ns)

    def write_json_bytes(
        self,
        topic: str,
        data: bytes,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        _check_times(log_time_ns, publish_time_ns)
        with self._lock:
            self._check_open()
            if topic not in self._json_topics:
                raise ValueError(f"topic {topic!r} is not a JSON topic: call add_json_topic first")
            self._queue((_JSON, topic, data, log_time_ns, publish_time_ns), log_time_ns)

    def write_json_format(
        self, topic: str, template: str, values: tuple[Any, ...], *, log_time_ns: int
    ) -> None:
        """`RecordingWriter.write_json_format`: the child formats the JSON."""
        _check_time(log_time_ns)
        with self._lock:
            self._check_open()
            if topic not in self._json_topics:
                raise ValueError(f"topic {topic!r} is not a JSON topic: call add_json_topic first")
            self._queue((_JSON_FORMAT, topic, template, values, log_time_ns), log_time_ns)

    def write(
        self,
        topic: str,
        value: FoxgloveValue,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        check_topic(topic)
        _check_times(log_time_ns, publish_time_ns)
        kind = type(value)
        if kind not in FOXGLOVE_TYPES:
            raise ValueError(f"topic {topic!r}: {kind.__name__} is not a Foxglove value")
        # the child encodes every value (a frame's PNG and a model's GLB too), off the
        # flight's path: the flight's process never imports Protobuf
        with self._lock:
            self._check_open()
            if topic not in self._protobuf_topics:
                self._check_kind(topic, kind)
                self._protobuf_topics.add(topic)
                # the child makes the schema, off the flight's path
                self._add((_PROTO_TOPIC, topic, kind))
            elif self._topic_kind[topic] is not kind:
                raise ValueError(f"topic {topic!r} carries {self._topic_kind[topic]!r}, not {kind}")
            raw = value.raw if kind is CompressedImage else None  # type: ignore[union-attr]
            if raw is None:
                self._queue((_ENCODE, topic, value, log_time_ns, publish_time_ns), log_time_ns)
                return
            # a frame's pixels go down the pipe as they are, not copied into the pickle
            image = value  # a CompressedImage
            pixels = pickle.PickleBuffer(raw.pixels)
            fields = (image.data, image.format, image.frame_id, raw.height_px, raw.width_px)  # type: ignore[union-attr]
            self._queue(
                (_ENCODE_RAW, topic, fields, pixels, log_time_ns, publish_time_ns), log_time_ns
            )

    def write_mavlink(
        self,
        frame: bytes,
        *,
        direction: Direction,
        log_time_ns: int,
        publish_time_ns: int | None = None,
        decoded: Any = None,  # noqa: ARG002 - the child decodes the frame itself
    ) -> None:
        """`RecordingWriter.write_mavlink`; ``decoded`` is not used: the child decodes the
        frame for its JSON view (on another core)."""
        if type(log_time_ns) is not int or not 0 < log_time_ns < _END_NS:
            _check_time(log_time_ns)
        if publish_time_ns is not None:
            _check_time(publish_time_ns, "publish_time_ns")
        if type(frame) is not bytes:
            frame = bytes(frame)
        with self._lock:
            if self._closed or self._failure is not None:
                self._check_open()
            if publish_time_ns is None:
                self._frames.append(frame)
                self._frame_ops.append(_MAV_IN if direction is Direction.IN else _MAV_OUT)
                self._frame_times.append(log_time_ns)
                if log_time_ns >= self._ship_at or len(self._frames) >= BATCH_CALLS:
                    self._ship(log_time_ns)
                return
            op = _MAV_PUBLISHED_IN if direction is Direction.IN else _MAV_PUBLISHED_OUT
            self._queue((op, frame, log_time_ns, publish_time_ns), log_time_ns)

    def mavlink_tap(
        self, clock_ns: Callable[[], int]
    ) -> Callable[[str, list[bytes], list[Any] | None], None]:
        """`write_mavlink` as a link's tap, the frames of each call stamped ``clock_ns()``; the
        decoded messages are not used (the child decodes the frames on another core)."""
        ops = {"in": _MAV_IN, "out": _MAV_OUT}
        lock, frames, frame_ops, frame_times = (
            self._lock,
            self._frames,
            self._frame_ops,
            self._frame_times,
        )

        def tap(direction: str, tapped: list[bytes], _decoded: list[Any] | None) -> None:
            t = clock_ns()
            if type(t) is not int or not 0 < t < _END_NS:
                _check_time(t)
            n = len(tapped)
            for frame in tapped:
                if type(frame) is not bytes:
                    tapped = [bytes(f) for f in tapped]
                    break
            with lock:
                if self._closed or self._failure is not None:
                    self._check_open()
                frames.extend(tapped)
                frame_ops.extend(bytes((ops[direction],)) * n)
                frame_times.extend(itertools.repeat(t, n))
                if t >= self._ship_at or len(frames) >= BATCH_CALLS:
                    self._ship(t)

        return tap

    def write_vehicle(
        self,
        pos_enu_m: tuple[float, float, float],
        heading_deg: float,
        origin: GeoPoint | None,
        *,
        log_time_ns: int,
    ) -> None:
        """`RecordingWriter.write_vehicle`: the child makes the pose and the fix."""
        _check_time(log_time_ns)
        with self._lock:
            self._check_open()
            if not self._vehicle:  # the topics it writes carry these from now on
                self._vehicle = True
                self._check_kind(POSE, PosesInFrame)
                self._check_kind(FIX, LocationFix)
            if origin is not self._origin:  # the child keeps the origin until it moves
                self._origin = origin
                self._add((_ORIGIN, origin))
            self._queue((_VEHICLE, pos_enu_m, heading_deg, log_time_ns), log_time_ns)

    # --- internals (called with the lock held) -----------------------------------------------

    def _check_kind(self, topic: str, kind: Any) -> None:
        """Raise `ValueError` if ``topic`` carries another kind; else it carries ``kind``."""
        known = self._topic_kind.setdefault(topic, kind)
        if known is not kind:
            raise ValueError(f"topic {topic!r} carries {known!r}, not {kind}")

    def _check_open(self) -> None:
        if self._failure is not None:
            raise self._failure
        if self._closed:
            raise ValueError(f"{self.path}: the recording is closed")

    def _add(self, item: tuple[Any, ...]) -> None:
        """Add one call to the batch, after the frames tapped so far."""
        self._batch.append(item)
        self._at.append(len(self._frames))

    def _queue(self, item: tuple[Any, ...], log_time_ns: int) -> None:
        """Add one call to the batch; ship the batch once a batch's log time or size is
        reached."""
        self._add(item)
        if log_time_ns >= self._ship_at or len(self._batch) >= BATCH_CALLS:
            self._ship(log_time_ns)

    def _ship(self, log_time_ns: int) -> None:
        """Send the batch down the pipe (waiting if the pipe is full); a child that ended
        shows as a broken pipe. The columns are emptied in place: a tap holds them."""
        frames, times = self._frames, self._frame_times
        batch = (
            self._batch,
            self._at,
            b"".join(frames),
            array("I", map(len, frames)),
            bytes(self._frame_ops),
            times.tobytes(),
        )
        self._batch, self._at = [], array("I")
        frames.clear()
        del self._frame_ops[:], times[:]
        self._ship_at = log_time_ns + BATCH_NS
        self._send(batch)

    def _send(self, value: Any) -> None:
        """Pickle ``value`` and write it to the pipe, framed, without copying it again."""
        pending = self._pending
        pending.extend(map(memoryview, _framed(value)))
        try:
            while pending:
                written = os.writev(self._out, pending)
                while written:  # drop what was written from the front
                    if written < len(pending[0]):
                        pending[0] = pending[0][written:]
                        break
                    written -= len(pending.pop(0))
        except BrokenPipeError:
            self._child_ended()
        except OSError as exc:
            self._fail(f"cannot hand the recording to its writer process: {exc.strerror or exc}")
        # anything else (Ctrl-C mid-write) leaves the rest in _pending: the next send ends it

    def _wake_child(self) -> None:
        """Have the child look at the pipe now, not at its next poll: the flight waits."""
        with contextlib.suppress(OSError):  # full: it is awake already; closed: it ended
            os.write(self._wake, b"w")

    def _reply(self) -> tuple[Any, ...]:
        """The child's answer to a flush or close; raises its failure."""
        try:
            reply = pickle.load(self._replies)
        except (EOFError, pickle.UnpicklingError, OSError):
            self._child_ended()
        if reply[0] == "error":
            self._fail(reply[2], reply[1])
        return tuple(reply)

    def _child_ended(self) -> NoReturn:
        """The child stopped early: raise its reason, or say how it ended."""
        with contextlib.suppress(EOFError, pickle.UnpicklingError, OSError):
            reply = pickle.load(self._replies)
            if reply[0] == "error":
                self._fail(reply[2], reply[1])
        code = self._proc.wait()
        self._fail(f"the recording's writer process ended unexpectedly (exit code {code})")

    def _fail(self, problem: str, path: str | None = None) -> NoReturn:
        if self._failure is None:
            self._failure = RecordingError(path or self.path, problem)
        raise self._failure


def _framed(value: Any) -> list[bytes | memoryview]:
    """``value`` as it travels down the pipe: the sizes of its pickle and of the buffers
    kept out of it (a frame's pixels, as `pickle.PickleBuffer`), then the pickle, then
    those buffers, not copied."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(value, protocol=5, buffer_callback=buffers.append)
    raws = [buffer.raw() for buffer in buffers]
    sizes = struct.pack(f"<{len(raws)}Q", *(raw.nbytes for raw in raws))
    return [_HEADER.pack(len(data), len(raws)) + sizes, data, *raws]


def _spawn(file: BinaryIO, wake: int) -> subprocess.Popen[bytes]:
    try:
        proc = subprocess.Popen(
            [sys.executable, "-c", _CHILD, json.dumps(sys.path)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            pass_fds=(file.fileno(), wake),
            start_new_session=True,  # Ctrl-C is the flight's to handle, not the writer's
            bufsize=0,
        )
    except OSError as exc:
        raise RecordingError(
            file.name, f"cannot start the recording's writer process: {exc.strerror or exc}"
        ) from exc
    assert proc.stdin is not None
    with contextlib.suppress(OSError):  # a smaller pipe only makes the flight wait sooner
        fcntl.fcntl(proc.stdin.fileno(), fcntl.F_SETPIPE_SZ, PIPE_BYTES)
    return proc


def _abandon(proc: subprocess.Popen[bytes], wake: int) -> None:
    """End the pipes (the child then writes what it holds and exits) and reap the child."""
    _release(proc, wake, wait=True)


def _release(proc: subprocess.Popen[bytes], wake: int, *, wait: bool) -> None:
    """End the pipes and reap the child: waiting for it, or by a thread of its own."""
    with contextlib.suppress(OSError):
        os.close(wake)
    for stream in (proc.stdin, proc.stdout):
        if stream is not None:
            with contextlib.suppress(OSError):
                stream.close()
    if wait:
        proc.wait()
    elif proc.poll() is None:
        threading.Thread(target=proc.wait, name="uavtool-recording-reaper", daemon=True).start()
