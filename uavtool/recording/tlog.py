"""MAVProxy's telemetry log (``.tlog``) to and from a recording's ``/mavlink/raw`` topic.

A tlog is a plain sequence of ``(8-byte big-endian µs since the Unix epoch, one MAVLink
frame)`` pairs; MAVProxy, MAVExplorer, mavlogdump and QGroundControl read and write it.
Frames are parsed here from their headers (no `mavutil`, which sets process-wide
environment variables); pymavlink's dialect module only checks CRCs while resynchronising
after garbage.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

from uavtool.recording.errors import TlogError, UnknownSchemaError, create_file, write_failed
from uavtool.recording.files import NotRegularFileError, atomic_output, open_input
from uavtool.recording.reader import RecordingReader
from uavtool.recording.schemas import DEFAULT_DIALECT, MAVLINK_RAW, MavlinkDecoder
from uavtool.recording.values import Direction, MavlinkFrame
from uavtool.recording.writer import RecordingWriter

_STAMP = struct.Struct(">Q")
_V2, _V1 = 0xFD, 0xFE
_SIGNED = 0x01
GCS_SYSID = 255  # MAVProxy's and QGroundControl's default system id


@dataclass(frozen=True, slots=True)
class TlogResult:
    frames: int
    skipped_bytes: int  # garbage between frames or a cut frame at the end (import only)


def export_tlog(rec: str | Path, out: str | Path) -> TlogResult:
    """Write every ``/mavlink/raw`` frame of ``rec``, both directions in recorded order, to a
    tlog stamped with each frame's log time. ``out`` appears only once complete. Raises
    `TopicNotFoundError` without MAVLink, `SameFileError` if ``out`` is ``rec``,
    `CorruptRecordingError` if frames cannot be read, `RecordingError` if ``out`` cannot be
    written."""
    with RecordingReader(rec) as reader:
        messages = reader.messages([MAVLINK_RAW])
        count = 0
        with atomic_output(out, inputs=[rec]) as tmp:
            f = create_file(tmp)
            try:
                with f:
                    for message in messages:
                        frame = reader.decode(message)
                        if not isinstance(frame, MavlinkFrame):
                            raise UnknownSchemaError(
                                rec,
                                f"{MAVLINK_RAW} has encoding {message.channel.message_encoding!r}",
                            )
                        f.write(_STAMP.pack(message.log_time_ns // 1000))
                        f.write(frame.data)
                        count += 1
            except OSError as exc:
                raise write_failed(out, exc) from None
    return TlogResult(count, 0)


def _frame_length(buf: bytes, pos: int) -> int | None:
    if pos + 3 > len(buf):
        return None
    stx = buf[pos]
    if stx == _V2:
        return 12 + buf[pos + 1] + (13 if buf[pos + 2] & _SIGNED else 0)
    if stx == _V1:
        return 8 + buf[pos + 1]
    return None


def read_tlog(
    path: str | Path, *, dialect: str = DEFAULT_DIALECT
) -> tuple[list[tuple[int, bytes]], int]:
    """``([(time_us, frame), …], skipped_bytes)`` of a tlog. Raises `TlogError`."""
    try:
        with open_input(path) as f:
            buf = f.read()
    except NotRegularFileError as exc:
        raise TlogError(path, str(exc).removeprefix(f"{path}: ")) from None
    except OSError as exc:
        raise TlogError(path, f"cannot open: {exc.strerror}") from exc
    if not buf:
        raise TlogError(path, "empty file")
    decoder = MavlinkDecoder(dialect)
    frames: list[tuple[int, bytes]] = []
    pos, skipped, in_sync = 0, 0, False
    while pos + 8 < len(buf):
        length = _frame_length(buf, pos + 8)
        end = pos + 8 + (length or 0)
        ok = length is not None and end <= len(buf)
        if ok and not in_sync:  # after garbage, only trust a frame whose CRC checks out
            ok = decoder.decode(buf[pos + 8 : end]) is not None
        if not ok:
            pos, skipped, in_sync = pos + 1, skipped + 1, False
            continue
        frames.append((_STAMP.unpack_from(buf, pos)[0], buf[pos + 8 : end]))
        pos, in_sync = end, True
    skipped += len(buf) - pos
    if not frames:
        raise TlogError(path, "no MAVLink frames found: not a .tlog (8-byte time + frame) file")
    return frames, skipped


def import_tlog(
    tlog: str | Path, out: str | Path, *, gcs_sysid: int = GCS_SYSID, dialect: str = DEFAULT_DIALECT
) -> TlogResult:
    """Turn a tlog into a recording: frames byte for byte on ``/mavlink/raw`` plus their
    decoded JSON channels. Frames from ``gcs_sysid`` count as sent (``out``), all others as
    received (``in``). Log time = the tlog's time stamp."""
    frames, skipped = read_tlog(tlog, dialect=dialect)
    meta = {"import": {"source": Path(tlog).name, "format": "tlog", "gcs_sysid": str(gcs_sysid)}}
    with (
        atomic_output(out, inputs=[tlog]) as tmp,
        RecordingWriter(tmp, metadata=meta, dialect=dialect, fsync=False) as writer,
    ):
        for time_us, frame in frames:
            sysid = frame[5] if frame[0] == _V2 else frame[3]
            direction = Direction.OUT if sysid == gcs_sysid else Direction.IN
            writer.write_mavlink(frame, direction=direction, log_time_ns=max(time_us * 1000, 1))
    return TlogResult(len(frames), skipped)
