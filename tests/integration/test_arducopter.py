"""``uavtool fly`` against ArduPilot's own ArduCopter SITL, when ``UAVTOOL_ARDUCOPTER`` names
a built ``arducopter`` binary (``./waf copter`` in an ArduPilot tree); skipped otherwise.

Without a mount the run must stop on the ground with exit 2 and the fix; with a servo mount
in a defaults file it must complete. ArduCopter runs ``SPEEDUP`` times faster than real time
(see :mod:`tests.integration.peers`).
"""

from __future__ import annotations

import subprocess
from contextlib import ExitStack
from pathlib import Path

import pytest

from tests.integration.peers import (
    ARDUCOPTER,
    arducopter,
    check_photo_poses,
    fly,
    fly_fleet_search,
)
from uavtool.geo import GeoPoint, enu_from_geo, geo_from_enu
from uavtool.recording import LocationFix, RecordingReader
from uavtool.recording.topics import FIX

pytestmark = pytest.mark.skipif(
    not ARDUCOPTER or not Path(ARDUCOPTER).is_file(),
    reason="UAVTOOL_ARDUCOPTER does not name a built arducopter binary",
)
MOUNT_PARM = (
    "MNT1_TYPE 1\nMNT1_PITCH_MIN -90\nMNT1_PITCH_MAX 0\nSERVO9_FUNCTION 7\nSERVO10_FUNCTION 6\n"
)
HOME = "50.0647,19.945,219,0"  # the paper scene's home (the scene follows the vehicle anyway)


def _fly(port: int, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    return fly(f"tcp:127.0.0.1:{port}", tmp_path)


def test_without_a_mount_exit_2_on_the_ground(tmp_path: Path) -> None:
    with arducopter(tmp_path, home=HOME) as port:
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
    with arducopter(tmp_path, params=MOUNT_PARM, home=HOME) as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    # two overviews, the look at red (the target's hue first), the top, front, right, diagonal
    check_photo_poses(tmp_path / "f.mcap", at_least=7)


def test_a_vehicle_elsewhere_flies_the_scene_at_its_home(tmp_path: Path) -> None:
    """ArduPilot's own default home (Canberra), 16,000 km from the paper scene's origin: the
    scene is placed at the vehicle's home (--scene-origin vehicle, the default) and the
    mission completes; the recording says which origin it used."""
    with arducopter(tmp_path, params=MOUNT_PARM, home="-35.363261,149.165230,584,353") as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    assert "placed at the vehicle's home" in result.stdout + result.stderr
    with RecordingReader(tmp_path / "f.mcap") as reader:
        vehicle = dict(reader.metadata)["vehicle"]
    assert vehicle["scene_origin"] == "vehicle-home"


def test_beside_the_date_line_the_mission_flies_across_it(tmp_path: Path) -> None:
    """Home 8 m west of the 180th meridian: the target stands across it, at longitudes near
    -180°. ArduCopter takes positions there (its own longitude arithmetic wraps), and uavtool
    must send them so: the mission completes and every fix recorded is beside home."""
    home = GeoPoint(50.0647, 179.999888, 219.0)
    with arducopter(tmp_path, params=MOUNT_PARM, home="50.0647,179.999888,219,0") as port:
        result = _fly(port, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    assert "correct: the target is 'red'" in result.stdout
    west = east = 0
    with RecordingReader(tmp_path / "f.mcap") as reader:
        for entry in reader.entries([FIX]):
            fix = entry.value
            assert isinstance(fix, LocationFix)
            e, n, _ = enu_from_geo(home, GeoPoint(fix.latitude_deg, fix.longitude_deg, 0.0))
            assert abs(e) < 100.0 and abs(n) < 100.0
            west += fix.longitude_deg > 0
            east += fix.longitude_deg < 0  # across the line
    assert west and east


def test_three_arducopters_fly_the_fleet_search(tmp_path: Path) -> None:
    """Three ArduCopter SITL instances (``-I0``, ``-I1``, ``-I2``; MAV_SYSID 1–3, named
    SYSID_THISMAV before 4.7; homes 10 m apart to the east, as ``sim_vehicle.py --count 3
    --auto-offset-line 90,10`` starts them) fly the fleet's search: the right building found
    and modelled, the vehicles kept apart, one recording that replays identically."""
    start = GeoPoint(50.0647, 19.945, 219.0)
    with ExitStack() as stack:
        ports = []
        for i in range(3):
            home = geo_from_enu(start, 10.0 * i, 0.0, 0.0)
            folder = tmp_path / f"v{i}"
            folder.mkdir()
            ports.append(
                stack.enter_context(
                    arducopter(
                        folder,
                        params=MOUNT_PARM + f"MAV_SYSID {i + 1}\n",
                        home=f"{home.lat_deg:.7f},{home.lon_deg:.7f},219,0",
                        instance=i,
                    )
                )
            )
        fly_fleet_search([f"tcp:127.0.0.1:{p}" for p in ports], tmp_path)
