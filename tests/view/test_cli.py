"""`uavtool view` errors: one line on stderr, exit code 2, and what to do instead."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.recording import RecordingWriter


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_listed_with_an_example() -> None:
    code, out, _ = _run("--help")
    assert code == 0 and "view" in out
    code, out, _ = _run("view", "--help")
    assert code == 0
    assert "uavtool view recordings/golden/paper.mcap --web" in out


def test_not_a_recording(tmp_path: Path) -> None:
    bad = tmp_path / "notes.mcap"
    bad.write_text("hello")
    code, _, err = _run("view", str(bad), "--save", str(tmp_path / "x.rrd"))
    assert code == 2
    assert err.startswith(f"uavtool: error: {bad}") and err.count("\n") == 1


def test_missing_file(tmp_path: Path) -> None:
    code, _, err = _run("view", str(tmp_path / "nope.mcap"), "--save", str(tmp_path / "x.rrd"))
    assert code == 2
    assert "nope.mcap" in err and err.count("\n") == 1


def test_a_recording_without_a_mission(tmp_path: Path) -> None:
    path = tmp_path / "other.mcap"
    with RecordingWriter(path, fsync=False) as writer:
        writer.add_json_topic("/notes", schema_name="note", schema={"type": "object"})
        writer.write_json("/notes", {"text": "hi"}, log_time_ns=1)
    code, _, err = _run("view", str(path), "--save", str(tmp_path / "x.rrd"))
    assert code == 2
    assert (
        err == f"uavtool: error: {path}: no /mission/observations topic: not a mission recording\n"
    )


def test_save_and_web_exclude_each_other(tmp_path: Path) -> None:
    code, _, err = _run("view", "x.mcap", "--save", str(tmp_path / "x.rrd"), "--web")
    assert code == 2
    assert "--save and --web exclude each other" in err


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the display check is Linux's")
def test_no_display_for_the_native_viewer(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    code, _, err = _run("view", "x.mcap")
    assert code == 2
    assert err == "uavtool: error: no display for the native viewer: use --web or --save OUT.rrd\n"
