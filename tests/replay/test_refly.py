"""Re-fly: a recording's configuration flown again from its metadata, the new recording
compared with the old one message by message."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from click.testing import CliRunner

from tests.recording.sample import write_sample
from uavtool.cli import cli
from uavtool.recording import RecordingReader, RecordingWriter
from uavtool.replay.refly import compare_recordings
from uavtool.sitl.lockstep import SIM_EPOCH_NS

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def test_refly_cli_reports_identical(tmp_path: Path) -> None:
    out = tmp_path / "again.mcap"
    result = CliRunner().invoke(cli, ["replay", "--refly", str(GOLDEN), "--output", str(out)])
    assert result.exit_code == 0, result.output
    assert "identical: the new recording equals the old one" in result.output
    assert out.exists()


def test_a_no_gimbal_flight_re_flies_the_same(tmp_path: Path) -> None:
    """The camera fixed straight down (no mount at boot, photo poses from the attitude) is
    in the recording, so the flight flown again is the same one (before, re-flown with a
    gimbal: 140.9 s instead of 172.9 s)."""
    flown, again = tmp_path / "fixed.mcap", tmp_path / "again.mcap"
    first = CliRunner().invoke(cli, ["fly", "-q", "--no-gimbal", "--output", str(flown)])
    assert first.exit_code == 3, first.output  # partial: no model without a gimbal
    result = CliRunner().invoke(cli, ["replay", "--refly", str(flown), "--output", str(again)])
    assert result.exit_code == 0, result.output
    assert "identical: the new recording equals the old one" in result.output


def test_refly_refuses_what_lockstep_did_not_fly(tmp_path: Path) -> None:
    sample = tmp_path / "sample.mcap"
    write_sample(sample)
    result = CliRunner().invoke(cli, ["replay", "--refly", str(sample)])
    assert result.exit_code == 2, result.output
    assert "not a lockstep flight of the built-in vehicle" in result.output
    assert "Traceback" not in result.output


def test_refly_takes_no_overrides() -> None:
    result = CliRunner().invoke(cli, ["replay", "--refly", str(GOLDEN), "--set", "a.b=1"])
    assert result.exit_code == 2
    assert "--refly" in result.output


def _write(path: Path, payloads: list[Mapping[str, Any]]) -> Path:
    with RecordingWriter(path, metadata={"flight": {"seed": "0"}}) as writer:
        writer.add_json_topic("/t", schema_name="t", schema={"type": "object"})
        for i, payload in enumerate(payloads):
            writer.write_json("/t", payload, log_time_ns=SIM_EPOCH_NS + i * 100_000_000)
    return path


def test_compare_names_the_first_differing_field(tmp_path: Path) -> None:
    a = _write(tmp_path / "a.mcap", [{"x": 1}, {"x": 2, "p": [0.5, 1.5]}])
    b = _write(tmp_path / "b.mcap", [{"x": 1}, {"x": 2, "p": [0.5, 1.25]}])
    count, diff = compare_recordings(a, b)
    assert count == 1
    assert diff == "message 1 (/t, vehicle time 0.100 s): p[1]: 1.5 recorded, 1.25 re-flown"


def test_compare_notices_a_missing_message(tmp_path: Path) -> None:
    a = _write(tmp_path / "a.mcap", [{"x": 1}, {"x": 2}])
    b = _write(tmp_path / "b.mcap", [{"x": 1}])
    assert compare_recordings(a, b) == (
        1,
        "the recorded flight has more messages, from message 1 (/t, vehicle time 0.100 s)",
    )
    assert compare_recordings(a, a) == (2, None)


def test_compare_ignores_the_software_version_only(tmp_path: Path) -> None:
    for i, (version, params) in enumerate([("0.1.0", "a"), ("9.9.9", "a"), ("0.1.0", "b")]):
        meta = {"mission": {"tool_version": version, "params": params}}
        with RecordingWriter(tmp_path / f"{i}.mcap", metadata=meta):
            pass
    assert compare_recordings(tmp_path / "0.mcap", tmp_path / "1.mcap") == (0, None)
    _, diff = compare_recordings(tmp_path / "0.mcap", tmp_path / "2.mcap")
    assert diff == 'metadata mission.params: "a" recorded, "b" re-flown'


def _crafted(path: Path, **changes: dict[str, str]) -> Path:
    """The golden's metadata with ``changes`` merged in, and nothing else: what a hostile
    recording could say (its CRCs are right)."""
    with RecordingReader(GOLDEN) as reader:
        meta = {name: dict(pairs) for name, pairs in reader.metadata if name != "uavtool"}
    for name, pairs in changes.items():
        meta[name] = {**meta[name], **pairs}
    with RecordingWriter(path, metadata=meta, fsync=False) as writer:
        writer.add_json_topic("/mission/observations", schema_name="x", schema={})
        writer.write_json("/mission/observations", {"step": 1}, log_time_ns=SIM_EPOCH_NS + 1)
    return path


def test_refly_never_hands_a_recorded_camera_to_opencv(tmp_path: Path) -> None:
    """A recording's camera would be opened by OpenCV/FFmpeg: a URL it fetches, a device, a
    file. Only the simulated camera is flown again; nothing is opened."""
    for camera in ("http://127.0.0.1:9/x.mjpg", "opencv:0", "/etc/passwd", "\x1b]52;c;x\x07"):
        crafted = _crafted(tmp_path / "camera.mcap", vehicle={"camera": camera})
        result = CliRunner().invoke(cli, ["replay", "--refly", str(crafted)])
        assert result.exit_code == 2, result.output
        assert "only a flight with the simulated camera can be flown again" in result.output
        assert "\x1b" not in result.output and "\x07" not in result.output


def test_refly_refuses_a_camera_size_before_allocating_it(tmp_path: Path) -> None:
    crafted = _crafted(tmp_path / "big.mcap", flight={"size_px": "[20000, 20000]"})
    result = CliRunner().invoke(cli, ["replay", "--refly", str(crafted)])
    assert result.exit_code == 2, result.output
    assert "flight.size_px is malformed: 20000x20000 is outside 16..8192 pixels a side" in (
        result.output
    )
