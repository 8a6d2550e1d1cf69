"""A camera that cannot be opened is one line from us, not OpenCV's and FFmpeg's logs of every
backend they tried first (those are written by C code, so the test runs the command)."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize("camera", ["opencv:7", "http://127.0.0.1:9/x.mjpg"])
def test_a_camera_that_does_not_open_is_one_line(camera: str) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "uavtool", "fly", "--camera", camera, "--no-record"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        f"uavtool: error: camera opencv:{camera.removeprefix('opencv:')}: cannot open it or "
        "read a frame"
    ]
