"""``uavtool fly`` and ``uavtool record`` against PX4's own SITL with SIH (its built-in
simulator), when ``UAVTOOL_PX4`` names its build (see :mod:`tests.integration.peers`);
skipped otherwise. The same mission, with no PX4 branch in it: the autopilot adapter speaks
PX4's modes, take-off, DO_REPOSITION, gimbal manager and parameter names."""

from __future__ import annotations

import itertools
import subprocess
import time
from contextlib import ExitStack
from pathlib import Path

import pytest

from tests.integration.peers import (
    PX4,
    PX4_GIMBAL,
    check_photo_poses,
    fly,
    fly_fleet_search,
    px4,
    uavtool,
)
from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.recording import LogEntry, RecordingReader
from uavtool.recording.topics import TELEMETRY, VEHICLE_EVENTS

pytestmark = pytest.mark.skipif(
    not PX4 or not Path(PX4).exists(),
    reason="UAVTOOL_PX4 does not name PX4's SITL build (px4_sitl_default or its .tar.gz)",
)
PX4_GCS_PORT = 14550
"""Where PX4 SITL's ground-station link sends (QGroundControl's port)."""


def test_without_a_gimbal_exit_2_on_the_ground_naming_px4_parameters(tmp_path: Path) -> None:
    with px4(tmp_path) as port:
        result = fly(f"udpin:0.0.0.0:{port}", tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "MNT_MODE_IN=4" in result.stderr and "reboot PX4" in result.stderr
    assert "MNT1_" not in result.stderr and "SERVO" not in result.stderr  # ArduPilot's names
    assert "taking off" not in result.stdout
    assert len(result.stderr.strip().splitlines()) == 1


def test_px4s_geofence_below_the_second_overview_stops_the_run_on_the_ground(
    tmp_path: Path,
) -> None:
    """GF_ACTION (an integer PX4 sends bytewise) and GF_MAX_VER_DIST read from PX4 itself."""
    fenced = {**PX4_GIMBAL, "GF_ACTION": "2", "GF_MAX_VER_DIST": "60"}
    with px4(tmp_path, params=fenced) as port:
        result = fly(f"udpin:0.0.0.0:{port}", tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "GF_MAX_VER_DIST=60 m" in result.stderr and "set GF_MAX_VER_DIST=" in result.stderr
    assert "taking off" not in result.stdout


def test_with_a_gimbal_the_mission_completes_and_every_photo_is_where_its_pose_says(
    tmp_path: Path,
) -> None:
    """The poses come from PX4's GLOBAL_POSITION_INT and its gimbal's quaternion."""
    with px4(tmp_path, params=PX4_GIMBAL) as port:
        result = fly(f"udpin:0.0.0.0:{port}", tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "(PX4)" in result.stdout + result.stderr
    assert "outcome        completed" in result.stdout
    assert "correct: the target is 'red'" in result.stdout
    # two overviews, the look at red (the target's hue first), the top, front, right, diagonal
    check_photo_poses(tmp_path / "f.mcap", at_least=7)


def test_without_a_gimbal_no_gimbal_flies_the_search(tmp_path: Path) -> None:
    """A camera fixed straight down: the search only, the target found, no model (partial,
    exit 3), landed and disarmed at home."""
    with px4(tmp_path) as port:
        result = fly(f"udpin:0.0.0.0:{port}", tmp_path, "--no-gimbal")
    assert result.returncode == 3, result.stdout + result.stderr
    assert "outcome        partial: target found, no model" in result.stdout
    assert "correct: the target is 'red'" in result.stdout
    assert "landed and disarmed" in result.stdout


def test_record_records_a_px4_flight_flown_by_someone_else(tmp_path: Path) -> None:
    """``uavtool record`` on PX4's ground-station link while another program (here ``uavtool
    fly`` on the API link) flies the vehicle: the whole flight, in PX4's own mode names."""
    recording = tmp_path / "rec.mcap"
    with px4(tmp_path, params=PX4_GIMBAL) as port:
        recorder = subprocess.Popen(
            uavtool("record", "--connect", f"udpin:0.0.0.0:{PX4_GCS_PORT}", "-o",
                    str(recording), "--camera", "sim", "--until-landed", "--direct"),
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        time.sleep(3.0)
        flown = fly(f"udpin:0.0.0.0:{port}", tmp_path, "--no-gimbal")
        try:
            out, err = recorder.communicate(timeout=120)
        finally:
            recorder.kill()
    assert flown.returncode == 3, flown.stdout + flown.stderr
    assert recorder.returncode == 0, out + err
    events, heights = [], []
    with RecordingReader(recording) as reader:
        assert reader.health.whole
        for entry in reader.entries([VEHICLE_EVENTS, TELEMETRY]):
            if isinstance(entry.value, LogEntry):
                events.append(entry.value.message)
            elif entry.topic == TELEMETRY:
                heights.append(entry.value.payload["pos_enu_m"][2])  # type: ignore[union-attr]
    assert {"armed", "disarmed"} <= set(events), events
    assert any("→ AUTO.TAKEOFF" in e for e in events), events
    assert any("→ AUTO.RTL" in e for e in events), events
    # Landed at home's height, within the mission's own tolerance: SIH's barometer drifts, and
    # PX4's relative altitude read -1.1 m on the ground after one CI flight.
    assert max(heights) > 40.0 and abs(heights[-1]) <= 2.0


def test_a_failsafe_is_a_takeover_in_px4s_own_words(tmp_path: Path) -> None:
    """A battery that runs flat seconds after take-off (SIH's simulated battery): PX4's
    failsafe switches to RTL; the mission says so and stops commanding (pilot-takeover, exit
    1), and PX4's events — which pymavlink cannot decode — are printed in words, once each."""
    drains = {**PX4_GIMBAL, "SIM_BAT_MIN_PCT": "5", "SIM_BAT_DRAIN": "1"}
    with px4(tmp_path, params=drains) as port:
        result = fly(f"udpin:0.0.0.0:{port}", tmp_path)
    said = result.stdout + result.stderr
    assert result.returncode == 1, said
    assert "outcome        pilot-takeover: mode changed to RTL" in result.stdout
    assert "PX4's events metadata:" in said
    assert "vehicle: Critical battery level: switching to RTL" in said
    lines = [line for line in said.splitlines() if line.startswith("uavtool fly: vehicle:")]
    assert all(a != b for a, b in itertools.pairwise(lines)), lines  # said once, not twice


def test_three_px4s_fly_the_fleet_search(tmp_path: Path) -> None:
    """Three PX4 SITL instances (``px4 -i 0``, ``-i 1``, ``-i 2``: MAV_SYS_ID 1-3, API links
    on 14540-14542, as PX4's multi-vehicle SITL starts them; homes 10 m apart to the east)
    fly the fleet's search: the right building found and modelled, the vehicles kept apart,
    one recording that replays identically."""
    start = GeoPoint(47.397743, 8.545597, 489.55)  # PX4's own SITL home
    with ExitStack() as stack:
        ports = []
        for i in range(3):
            folder = tmp_path / f"v{i}"
            folder.mkdir()
            home = geo_from_enu(start, 10.0 * i, 0.0, 0.0)
            ports.append(stack.enter_context(px4(folder, params=PX4_GIMBAL, instance=i, home=home)))
        assert ports == [14540, 14541, 14542]
        fly_fleet_search([f"udpin:0.0.0.0:{p}" for p in ports], tmp_path)
