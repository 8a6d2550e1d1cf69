"""What a failed ``uavtool fly`` leaves: nothing when the mission never ran; a recording that
says it failed when the mission ran and then broke; never a file over one of its inputs."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.images import png_encode
from uavtool.recording import summarize
from uavtool.runner.fly import FlyConfig, fly
from uavtool.runner.runner import Runner


def test_no_heartbeat_leaves_no_recording(tmp_path: Path) -> None:
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    port = server.getsockname()[1]

    def silent() -> None:
        conn, _ = server.accept()
        with conn:
            time.sleep(3.0)

    threading.Thread(target=silent, daemon=True).start()
    rec = tmp_path / "flight.mcap"
    result = CliRunner().invoke(
        cli,
        ["fly", "--connect", f"tcp:127.0.0.1:{port}", "--timeout", "1", "--output", str(rec)],
    )
    server.close()
    assert result.exit_code == 2, result.output
    assert "no heartbeat" in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_run_that_breaks_keeps_its_recording_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def vanish(self: object) -> object:
        raise RuntimeError("the vehicle vanished")

    monkeypatch.setattr(Runner, "run", vanish)
    rec = tmp_path / "flight.mcap"
    with pytest.raises(RuntimeError, match="vanished"):
        fly(FlyConfig(record=rec))
    assert [p.name for p in tmp_path.iterdir()] == ["flight.mcap"]
    info = summarize(rec)
    assert info.whole and not info.damage
    assert info.outcome is not None
    assert info.outcome["status"] == "failed"
    assert "the vehicle vanished" in info.outcome["reason"]


def test_recording_over_the_target_picture_is_refused(tmp_path: Path) -> None:
    target = tmp_path / "target.png"
    target.write_bytes(png_encode(np.full((48, 64, 3), (200, 30, 30), np.uint8)))
    before = target.read_bytes()
    result = CliRunner().invoke(cli, ["fly", "--target", str(target), "--output", str(target)])
    assert result.exit_code == 2
    assert "writing it would destroy it" in result.output
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["target.png"]
