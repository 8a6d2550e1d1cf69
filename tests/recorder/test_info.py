"""`uavtool info` on a file from `uavtool record`: what stopped it, for how long, its frames
and photos — never "the mission did not finish", since there was no mission."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from tests.recorder.flight import STOPS, Recorded
from uavtool.cli import cli
from uavtool.recording import CompressedImage, RecordingReader, RecordingWriter
from uavtool.recording.topics import IMAGE


def _images(path: Path) -> int:
    with RecordingReader(path) as reader:
        return sum(isinstance(e.value, CompressedImage) for e in reader.entries([IMAGE]))


def test_info_shows_why_record_stopped_and_what_it_took(recorded: Recorded) -> None:
    result = CliRunner().invoke(cli, ["info", str(recorded.path)])
    assert result.exit_code == 0, result.output
    frames = _images(recorded.path)
    line = next(x for x in result.output.splitlines() if x.startswith("recorded:"))
    assert line.startswith("recorded:  by uavtool record (no mission), stopped: landed after ")
    assert f"; {frames} frames, {len(STOPS)} photos" in line
    assert "outcome:" not in result.output
    assert "did not finish" not in result.output

    data = json.loads(CliRunner().invoke(cli, ["info", "--json", str(recorded.path)]).output)
    assert data["from_record"] is True and data["outcome"] is None
    r = data["record_result"]
    assert (r["stopped"], r["frames"], r["photos"]) == ("landed", str(frames), str(len(STOPS)))
    assert 0 < float(r["duration_s"]) <= data["duration_s"] + 1.0


def test_a_record_file_without_its_result_was_killed_not_an_unfinished_mission(
    tmp_path: Path,
) -> None:
    # What `info --recover` rescues from a recorder killed by SIGKILL: its opening metadata only.
    path = tmp_path / "killed.mcap"
    with RecordingWriter(path, metadata={"record": {"camera": "sim"}}) as writer:
        writer.write(IMAGE, CompressedImage(b"png"), log_time_ns=1)
    result = CliRunner().invoke(cli, ["info", str(path)])
    assert result.exit_code == 0, result.output
    assert "recorded:  by uavtool record (no mission); no 'record_result'" in result.output
    assert "killed" in result.output and "did not finish" not in result.output
    data = json.loads(CliRunner().invoke(cli, ["info", "--json", str(path)]).output)
    assert data["from_record"] is True and data["record_result"] is None
