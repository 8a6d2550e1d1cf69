"""``uavtool fly`` against ArduPilot's own ArduCopter SITL, when ``UAVTOOL_ARDUCOPTER`` names
a built ``arducopter`` binary (``./waf copter`` in an ArduPilot tree); skipped otherwise.

Without a mount the run must stop on the ground with exit 2 and the fix; with a servo mount
in a defaults file it must complete. ArduCopter boots in ~20 s of sim time, so each flight
takes minutes of wall time.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from uavtool.camera import CameraPose
from uavtool.mission import Photo
from uavtool.recording import RecordingReader
from uavtool.replay import load_flight
from uavtool.world import load_scene, render

ARDUCOPTER = os.environ.get("UAVTOOL_ARDUCOPTER", "")
pytestmark = pytest.mark.skipif(
    not ARDUCOPTER or not Path(ARDUCOPTER).is_file(),
    reason="UAVTOOL_ARDUCOPTER does not name a built arducopter binary",
)
MOUNT_PARM = (
    "MNT1_TYPE 1\nMNT1_PITCH_MIN -90\nMNT1_PITCH_MAX 0\nSERVO9_FUNCTION 7\nSERVO10_FUNCTION 6\n"
)
HOME = "50.0647,19.945,219,0"  # the paper scene's home (the scene follows the vehicle anyway)


def _copter_defaults() -> Path:
    """ArduPilot's copter.parm: beside the binary (a prebuilt SITL, as ../shared/peers lays
    it out), else in the source tree the binary was built in (build/sitl/bin/arducopter)."""
    binary = Path(ARDUCOPTER).resolve()
    beside = binary.parent / "copter.parm"
    if beside.is_file():
        return beside
    return binary.parents[3] / "Tools" / "autotest" / "default_params" / "copter.parm"


@contextmanager
def arducopter(tmp_path: Path, *, mount: bool, home: str = HOME) -> Iterator[int]:
    defaults = [str(_copter_defaults())]
    if mount:
        parm = tmp_path / "mount.parm"
        parm.write_text(MOUNT_PARM)
        defaults.append(str(parm))
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    cmd = [
        ARDUCOPTER, "--model", "+", "--home", home, "--defaults", ",".join(defaults),
        "--serial0", f"tcp:{port}", "--wipe", "-I0",
    ]  # fmt: skip
    proc = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    try:
        time.sleep(2.0)
        yield port
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def _fly(port: int, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "uavtool", "fly", "--connect", f"tcp:127.0.0.1:{port}",
         "--timeout", "120", "--record", str(tmp_path / "f.mcap")],
        capture_output=True, text=True, timeout=1800, check=False,
    )  # fmt: skip


def test_without_a_mount_exit_2_on_the_ground(tmp_path: Path) -> None:
    with arducopter(tmp_path, mount=False) as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "MNT1_TYPE" in result.stderr and "reboot" in result.stderr
    assert "taking off" not in result.stdout


def test_with_a_mount_the_mission_completes_and_every_photo_is_where_its_pose_says(
    tmp_path: Path,
) -> None:
    """Each photo's pose comes from ArduCopter's attitude and gimbal quaternion (its servo
    mount reports pitch −90° with a little stabilising roll, where Euler angles are singular):
    nadir photos point straight down, side photos level, headings in [0, 360), and the scene
    rendered again at the pose recorded is the photo recorded — a heading off by 180° would
    give another picture."""
    with arducopter(tmp_path, mount=True) as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    flight = load_flight(tmp_path / "f.mcap")
    scene = load_scene("paper")  # placed at the vehicle's home: its own frame
    photos = [o for o in flight.observations if isinstance(o, Photo)]
    assert len(photos) >= 9
    for photo in photos:
        pose = photo.pose
        side = photo.tag.split("-")[0] in ("front", "right", "diagonal")
        assert abs(pose.pitch_deg - (0.0 if side else -90.0)) < 1.0, (photo.tag, pose)
        assert 0.0 <= pose.heading_deg < 360.0, (photo.tag, pose)
        again = render(scene, pose, photo.intrinsics).astype(np.int16)
        turned = CameraPose(pose.pos_enu_m, (pose.heading_deg + 180.0) % 360.0, pose.pitch_deg)
        other = render(scene, turned, photo.intrinsics).astype(np.int16)
        shot = photo.image_rgb.astype(np.int16)
        same, flipped = np.abs(shot - again).mean(), np.abs(shot - other).mean()
        assert same < 1.0 and (side or flipped > 5.0 * max(same, 0.2)), (photo.tag, same, flipped)


def test_a_vehicle_elsewhere_flies_the_scene_at_its_home(tmp_path: Path) -> None:
    """ArduPilot's own default home (Canberra), 16,000 km from the paper scene's origin: the
    scene is placed at the vehicle's home (--scene-origin vehicle, the default) and the
    mission completes; the recording says which origin it used."""
    with arducopter(tmp_path, mount=True, home="-35.363261,149.165230,584,353") as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    assert "placed at the vehicle's home" in result.stdout + result.stderr
    with RecordingReader(tmp_path / "f.mcap") as reader:
        vehicle = dict(reader.metadata)["vehicle"]
    assert vehicle["scene_origin"] == "vehicle-home"
