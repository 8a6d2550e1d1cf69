"""/mavlink/raw <-> MAVProxy .tlog, checked against pymavlink's own tlog reader."""

from __future__ import annotations

import json
import os
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from tests.recording.sample import T0_NS, mavlink_frames, write_sample
from uavtool.recording import (
    Direction,
    JsonDocument,
    RecordingReader,
    TlogError,
    TopicNotFoundError,
    export_tlog,
    import_tlog,
    summarize,
)
from uavtool.recording.info import format_info

# pymavlink's mavutil picks MAVLink 2 from an environment variable at import: run it in a
# child process so the test process stays clean.
_MAVUTIL_DUMP = """
import json, sys
from pymavlink import mavutil
log = mavutil.mavlink_connection(sys.argv[1], dialect="ardupilotmega")
out = []
while (msg := log.recv_msg()) is not None:
    out.append([msg.get_msgbuf().hex(), round(msg._timestamp * 1e6), msg.get_type()])
print(json.dumps(out))
"""


def _mavutil_read(path: Path) -> list[list[object]]:
    env = {**os.environ, "MAVLINK20": "1"}
    done = subprocess.run(
        [sys.executable, "-c", _MAVUTIL_DUMP, str(path)],
        capture_output=True,
        env=env,
        check=True,
        timeout=60,
    )
    result: list[list[object]] = json.loads(done.stdout)
    return result


def test_export_is_read_back_by_mavutil(tmp_path: Path) -> None:
    rec, tlog = tmp_path / "rec.mcap", tmp_path / "out.tlog"
    write_sample(rec, seconds=1.0)
    result = export_tlog(rec, tlog)
    frames = mavlink_frames(100)
    assert result.frames == len(frames)
    got = _mavutil_read(tlog)
    assert [bytes.fromhex(str(g[0])) for g in got] == [f for _, f in frames]
    assert [g[1] for g in got] == [(T0_NS + i * 10_000_000) // 1000 for i in range(100)]
    assert got[0][2] == "HEARTBEAT"


def _write_tlog(path: Path, frames: list[tuple[Direction, bytes]], garbage_at: int = -1) -> None:
    with path.open("wb") as f:
        for i, (_direction, frame) in enumerate(frames):
            if i == garbage_at:
                f.write(b"\xfd\x09junk between frames")
            f.write(struct.pack(">Q", 1_700_000_000_000_000 + i * 1000) + frame)


def test_import_keeps_every_frame_byte_for_byte(tmp_path: Path) -> None:
    tlog, rec = tmp_path / "flight.tlog", tmp_path / "rec.mcap"
    frames = mavlink_frames(200)
    _write_tlog(tlog, frames, garbage_at=50)
    result = import_tlog(tlog, rec)
    assert result.frames == 200
    assert result.skipped_bytes == len(b"\xfd\x09junk between frames")
    with RecordingReader(rec) as reader:
        raw = list(reader.entries(["/mavlink/raw"]))
        heartbeat = next(reader.entries(["/mavlink/out/HEARTBEAT"]))
        assert dict(reader.metadata)["import"]["source"] == "flight.tlog"
    assert [(e.value.direction, e.value.data) for e in raw] == frames  # type: ignore[union-attr]
    assert raw[7].log_time_ns == (1_700_000_000_000_000 + 7000) * 1000
    assert isinstance(heartbeat.value, JsonDocument)
    assert heartbeat.value.payload["header"]["sysid"] == 255
    report = format_info(summarize(rec))
    assert "imported:  a telemetry log" in report  # no mission ran: nothing "did not finish"
    assert "did not finish" not in report


def test_tlog_round_trip_is_lossless(tmp_path: Path) -> None:
    tlog = tmp_path / "flight.tlog"
    _write_tlog(tlog, mavlink_frames(120))
    import_tlog(tlog, tmp_path / "rec.mcap")
    export_tlog(tmp_path / "rec.mcap", tmp_path / "again.tlog")
    assert (tmp_path / "again.tlog").read_bytes() == tlog.read_bytes()


def test_bad_tlogs_and_recordings_without_mavlink(tmp_path: Path) -> None:
    empty, text = tmp_path / "empty.tlog", tmp_path / "notes.tlog"
    empty.write_bytes(b"")
    text.write_bytes(b"this is not a telemetry log at all\n" * 20)
    with pytest.raises(TlogError, match=re.escape("empty.tlog: empty file")):
        import_tlog(empty, tmp_path / "a.mcap")
    with pytest.raises(TlogError, match=re.escape("notes.tlog: no MAVLink frames")):
        import_tlog(text, tmp_path / "b.mcap")
    from uavtool.recording import CompressedImage, RecordingWriter

    with RecordingWriter(tmp_path / "images.mcap", fsync=False) as writer:
        writer.write("/camera/image", CompressedImage(b"png"), log_time_ns=1)
    with pytest.raises(TopicNotFoundError, match=re.escape("images.mcap: no topic '/mavlink/raw'")):
        export_tlog(tmp_path / "images.mcap", tmp_path / "x.tlog")
