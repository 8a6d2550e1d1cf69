"""The writer process of `uavtool.recording.process.ProcessWriter`: it reads the flight's
batches from its pipe (a thread of its own holds up to `BACKLOG_BYTES` read ahead) and makes
each call on a `RecordingWriter` (imported here only: the flight's process never needs it).
The module docstring of `uavtool.recording.process` says how the two sides work together."""

from __future__ import annotations

import os
import pickle
import queue
import select
import struct
import sys
import threading
import time
from array import array
from typing import Any

from uavtool.recording.errors import RecordingError
from uavtool.recording.process import (
    _CLOSE,
    _ENCODE,
    _ENCODE_RAW,
    _FLUSH,
    _HEADER,
    _JSON,
    _JSON_FORMAT,
    _JSON_TOPIC,
    _MAV_IN,
    _MAV_PUBLISHED_IN,
    _MAV_PUBLISHED_OUT,
    _METADATA,
    _ORIGIN,
    _PROTO_TOPIC,
    _VEHICLE,
    _Batch,
)
from uavtool.recording.protocol import foxglove_module
from uavtool.recording.values import CompressedImage, Direction, RgbImage

BACKLOG_BYTES = 64 << 20
"""Batches the child may hold read but not yet written: a flight that outruns its writer by
more waits at the pipe."""
POLL_S = (0.001, 0.02)
"""How long the child's reader sleeps when the pipe is empty: from the shortest, doubling
while it stays empty, to the longest. A reader asleep in ``read`` would be woken by each
batch, and the flight's process pays for the waking (~20 us a batch in a virtual machine);
a reader that looks every millisecond costs it nothing, and a few hundred wake-ups a second
of its own on the other core. A flush or a close, which the flight waits for, wakes it at
once: its sleep is a wait on a second pipe, the wake pipe, that only those write to."""


def _read_framed(fd: int, wake: int | None = None) -> tuple[Any, int]:
    """One framed value from the pipe ``fd``, and its size; `EOFError` at the pipe's end
    (or a frame cut short). Plain reads: no buffered stream's lock for a daemon thread to
    hold when the interpreter ends."""
    size, count = _HEADER.unpack(_read_exactly(fd, _HEADER.size, wake))
    sizes = struct.unpack(f"<{count}Q", _read_exactly(fd, 8 * count, wake))
    data = _read_exactly(fd, size, wake)
    buffers = [_read_exactly(fd, n, wake) for n in sizes]
    return pickle.loads(data, buffers=buffers), size + sum(sizes)


def _read_exactly(fd: int, size: int, wake: int | None = None) -> bytearray:
    """``size`` bytes from ``fd``; on a non-blocking ``fd``, sleeping `POLL_S` between
    looks while it is empty, or until the pipe ``wake`` has something to say."""
    data = bytearray(size)
    view = memoryview(data)
    done = 0
    pause = POLL_S[0]
    while done < size:
        try:
            n = os.readv(fd, [view[done:]])
        except BlockingIOError:
            if wake is None:
                time.sleep(pause)
            elif select.select((wake,), (), (), pause)[0]:
                if not os.read(wake, 4096):  # the flight's process closed it: sleep from now
                    wake = None
                pause = POLL_S[0]
                continue
            pause = min(2 * pause, POLL_S[1])
            continue
        if n == 0:
            raise EOFError
        done += n
        pause = POLL_S[0]
    return data


def serve() -> None:
    """The child's loop: an init tuple, then batches of calls on stdin; replies on stdout."""
    replies = os.fdopen(os.dup(1), "wb", buffering=0)
    sys.stdout = sys.stderr  # stdout carries replies only
    source = sys.stdin.fileno()

    def reply(*answer: Any) -> None:
        replies.write(pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL))

    (path, fd, wake, metadata, dialect, interval_ns, budget, fsync), _ = _read_framed(source)
    os.set_blocking(wake, False)
    batches = _Backlog(source, wake)  # the pipe drained from now on, while the writer is imported
    try:
        # the MCAP writer, imported here: the flight's process, which imports this module
        # too, never needs it
        from uavtool.recording.writer import RecordingWriter  # noqa: PLC0415

        writer = RecordingWriter(
            path,
            metadata=metadata,
            dialect=dialect,
            chunk_interval_ns=interval_ns,
            chunk_bytes=budget,
            fsync=fsync,
            file=os.fdopen(fd, "wb"),
        )
        _serve(writer, batches, reply)
    except RecordingError as exc:
        reply("error", exc.path, exc.problem)
    except Exception as exc:  # whatever it is, the flight must hear of it
        reply("error", path, f"the recording's writer failed: {type(exc).__name__}: {exc}")
    else:
        # the file is closed (or, the flight gone, its chunks flushed) and the reply sent: an
        # interpreter's orderly exit would keep the flight waiting ~50 ms more at its close
        os._exit(0)


class _Backlog:
    """Batches read from the pipe by a thread of the child's own, for its main thread to
    write: the pipe is drained while a photo is compressed (zlib and zstd let go of the
    GIL). At most `BACKLOG_BYTES` are held; `None` marks the pipe's end."""

    def __init__(self, source: int, wake: int) -> None:
        self._source, self._wake = source, wake
        self._batches: queue.SimpleQueue[tuple[_Batch, int] | None] = queue.SimpleQueue()
        self._room = threading.Semaphore(BACKLOG_BYTES >> 16)  # in 64 KiB units
        threading.Thread(target=self._read, name="uavtool-recording-reader", daemon=True).start()

    def _read(self) -> None:
        os.set_blocking(self._source, False)  # looked at, not waited on: `POLL_S`
        while True:
            try:
                batch, size = _read_framed(self._source, self._wake)
            except (EOFError, pickle.UnpicklingError, OSError):
                self._batches.put(None)
                return
            units = min(BACKLOG_BYTES, size) >> 16
            for _ in range(units):
                self._room.acquire()
            self._batches.put((batch, units))

    def next(self) -> _Batch | None:
        """The next batch, or `None` at the pipe's end."""
        item = self._batches.get()
        if item is None:
            return None
        batch, units = item
        if units:
            self._room.release(units)
        return batch


class _Frames:
    """A batch's MAVLink frames, in its columns, written in turn between its other calls."""

    def __init__(
        self, data: bytes, lengths: array[int], ops: bytes, times: array[int], write: Any
    ) -> None:
        self._data, self._lengths, self._ops, self._times = data, lengths, ops, times
        self._write = write
        self._next = self._offset = 0  # the next frame, and where it starts in data

    def write_to(self, stop: int) -> None:
        """Write the frames up to (not including) frame ``stop``."""
        data, lengths, ops, times, write = (
            self._data,
            self._lengths,
            self._ops,
            self._times,
            self._write,
        )
        inbound, outbound = Direction.IN, Direction.OUT
        frame, offset = self._next, self._offset
        while frame < stop:
            end = offset + lengths[frame]
            direction = inbound if ops[frame] == _MAV_IN else outbound
            write(data[offset:end], direction=direction, log_time_ns=times[frame])
            frame, offset = frame + 1, end
        self._next, self._offset = frame, offset


def _serve(writer: Any, source: _Backlog, reply: Any) -> None:
    protobuf: dict[str, tuple[str, bytes]] = {}  # topic -> (schema name, schema)
    write_mavlink, write_json, write_protobuf = (
        writer.write_mavlink,
        writer.write_json_bytes,
        writer.write_protobuf,
    )
    inbound, outbound = Direction.IN, Direction.OUT
    origin = None  # write_vehicle's, as the flight's last _ORIGIN set it
    while True:
        batch = source.next()
        if batch is None:
            # the flight's process ended without closing: keep what it sent, leave the file
            # unfinished (uavtool info --recover reads it)
            writer.flush()
            return
        calls, at, data, lengths, ops, times_bytes = batch
        times = array("Q")
        times.frombytes(times_bytes)
        frames = _Frames(data, lengths, ops, times, write_mavlink)
        for call, before in zip(calls, at, strict=True):
            frames.write_to(before)
            op = call[0]
            if op <= _MAV_PUBLISHED_OUT:  # _MAV_PUBLISHED_IN or _MAV_PUBLISHED_OUT
                direction = inbound if op == _MAV_PUBLISHED_IN else outbound
                write_mavlink(
                    call[1], direction=direction, log_time_ns=call[2], publish_time_ns=call[3]
                )
            elif op == _VEHICLE:
                writer.write_vehicle(call[1], call[2], origin, log_time_ns=call[3])
            elif op == _ORIGIN:
                origin = call[1]
            elif op == _ENCODE_RAW:
                data, fmt, frame_id, height, width = call[2]
                image = CompressedImage(
                    data, fmt, frame_id, RgbImage(bytes(call[3]), height, width)
                )
                name, schema = protobuf[call[1]]
                write_protobuf(
                    call[1],
                    foxglove_module().encode(image, call[4]),
                    schema_name=name,
                    schema=schema,
                    log_time_ns=call[4],
                    publish_time_ns=call[5],
                )
            elif op == _ENCODE:
                name, schema = protobuf[call[1]]
                write_protobuf(
                    call[1],
                    foxglove_module().encode(call[2], call[3]),
                    schema_name=name,
                    schema=schema,
                    log_time_ns=call[3],
                    publish_time_ns=call[4],
                )
            elif op == _JSON_FORMAT:
                write_json(call[1], (call[2] % call[3]).encode(), log_time_ns=call[4])
            elif op == _JSON:
                write_json(call[1], call[2], log_time_ns=call[3], publish_time_ns=call[4])
            elif op == _PROTO_TOPIC:
                foxglove = foxglove_module()
                protobuf[call[1]] = (foxglove.schema_name(call[2]), foxglove.schema_data(call[2]))
            elif op == _JSON_TOPIC:
                writer.add_json_topic(call[1], schema_name=call[2], schema=call[3])
            elif op == _METADATA:
                writer.add_metadata(call[1], call[2])
            elif op == _FLUSH:
                writer.flush()
                reply("flushed")
            elif op == _CLOSE:
                writer.close()
                reply("closed", writer.message_count)
                return
        frames.write_to(len(lengths))
