"""The geofence holds on the vehicle's position, in every mode, and says so in SYS_STATUS."""

from __future__ import annotations

import itertools
import math

import pytest

from tests.sitl.pilot import Pilot
from uavtool.geo import GeoPoint
from uavtool.mavlink import mavlink as M
from uavtool.sitl.shaping import stopping_distance as leash_m
from uavtool.sitl.state import Mode

GEOFENCE = M.MAV_SYS_STATUS_GEOFENCE
RTL, LAND = 6, 9


def _fenced(
    alt_max_m: float = 20.0, radius_m: float = 50.0, action: int = 1, *, avoid: int = 3
) -> Pilot:
    """A vehicle with the fence on; ``avoid`` 0 turns ArduCopter's stop-at-the-fence off, so
    that a velocity stream breaches it."""
    pilot = Pilot()
    for name, value in (
        ("FENCE_ENABLE", 1),
        ("FENCE_ALT_MAX", alt_max_m),
        ("FENCE_RADIUS", radius_m),
        ("FENCE_ACTION", action),
        ("AVOID_ENABLE", avoid),
    ):
        assert pilot.set_param(name, value).param_value == value
    return pilot


def _local_target(
    *, pos: tuple[float, float, float] = (0, 0, 0), vel: tuple[float, float, float] = (0, 0, 0)
) -> object:
    mask = 0b110111111000 if vel == (0, 0, 0) else 0b110111000111
    return M.MAVLink_set_position_target_local_ned_message(
        0, 1, 1, M.MAV_FRAME_LOCAL_NED, mask, *pos, *vel, 0, 0, 0, 0, 0
    )


@pytest.mark.parametrize(("action", "mode"), [(1, RTL), (2, LAND)])
def test_a_velocity_climb_stops_at_the_fence_and_triggers_its_action(
    action: int, mode: int
) -> None:
    pilot = _fenced(action=action, avoid=0)
    pilot.takeoff(5)
    peak = 0.0
    for _ in range(60):  # climb at full speed for 30 s: a stream a target check never sees
        pilot.send(_local_target(vel=(0, 0, -5)))
        pilot.run(0.5)
        peak = max(peak, pilot.alt_m())
    assert "Fence breached: Max Alt" in pilot.statustexts()
    assert pilot.mode() == mode
    # It stopped past FENCE_ALT_MAX (20 m) by its braking distance from 2.5 m/s at
    # WPNAV_ACCEL_Z (1 m/s²) and PSC_POSZ_P (1/s), not at 80 m.
    assert peak < 20.0 + leash_m(2.5, 1.0, 1.0) + 0.5
    assert pilot.alt_m() < 20.0


def _upload(pilot: Pilot, items: list[tuple[int, int, int, int, float]]) -> None:
    """(command, frame, lat_e7, lon_e7, alt) per item after home; answers MISSION_REQUEST_INT."""
    pilot.send(M.MAVLink_mission_count_message(1, 1, len(items) + 1, 0))
    for seq in range(len(items) + 1):
        request = pilot.of_type("MISSION_REQUEST_INT")[-1]
        assert request.seq == seq
        cmd, frame, x, y, z = (M.MAV_CMD_NAV_WAYPOINT, 0, 0, 0, 0.0) if seq == 0 else items[seq - 1]
        pilot.send(
            M.MAVLink_mission_item_int_message(1, 1, seq, frame, cmd, 0, 1, 0, 0, 0, 0, x, y, z, 0)
        )
    assert pilot.of_type("MISSION_ACK")[-1].type == M.MAV_MISSION_ACCEPTED


def test_an_auto_mission_far_and_high_stops_at_the_fence() -> None:
    pilot = _fenced(alt_max_m=30.0, radius_m=50.0)
    home = pilot.sitl.config.home
    far = GeoPoint(home.lat_deg + 0.018, home.lon_deg, 0)  # 2 km north, 500 m up
    rel = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    _upload(
        pilot,
        [(M.MAV_CMD_NAV_TAKEOFF, rel, 0, 0, 10.0), (16, rel, far.lat_e7, far.lon_e7, 500.0)],
    )
    assert pilot.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
    assert pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
    assert pilot.set_mode("AUTO").result == M.MAV_RESULT_ACCEPTED
    farthest_m = highest_m = 0.0
    for _ in range(120):
        pilot.run(0.5)
        n, e, d = pilot.sitl.autopilot.state.pos_ned_m
        farthest_m, highest_m = max(farthest_m, math.hypot(n, e)), max(highest_m, -d)
    assert any(t.startswith("Fence breached") for t in pilot.statustexts())
    assert pilot.mode() == RTL
    # It turned back at the 50 m circle and under the 30 m ceiling, each passed by its braking
    # distance (10 m/s at WPNAV_ACCEL, 2.5 m/s up at WPNAV_ACCEL_Z), not 2 km away at 500 m.
    assert farthest_m < 50.0 + leash_m(10.0, 1.0, 2.5) + 3.0
    assert highest_m < 30.0 + leash_m(2.5, 1.0, 1.0) + 0.5
    pilot.run_until(lambda p: not p.armed, 120, "landing at home")


def test_targets_below_ground_are_refused() -> None:
    pilot = Pilot()
    pilot.takeoff(10)
    target_before = pilot.sitl.autopilot.vehicle.target
    pilot.send(_local_target(pos=(0, 0, 50)))  # 50 m below home
    assert "below ground" in pilot.statustexts()[-1]
    pilot.send(
        M.MAVLink_set_position_target_global_int_message(
            0, 1, 1, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, 0b110111111000,
            pilot.sitl.config.home.lat_e7, pilot.sitl.config.home.lon_e7, -1e9,
            0, 0, 0, 0, 0, 0, 0, 0,
        )
    )  # fmt: skip
    assert "below ground" in pilot.statustexts()[-1]
    assert pilot.sitl.autopilot.vehicle.target == target_before
    home = pilot.sitl.config.home
    ack = pilot.command(
        M.MAV_CMD_DO_REPOSITION, -1, 0, 0, math.nan, home.lat_deg, home.lon_deg, -50
    )
    assert ack.result == M.MAV_RESULT_DENIED
    rel = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    pilot.send(M.MAVLink_mission_count_message(1, 1, 2, 0))
    pilot.send(M.MAVLink_mission_item_int_message(1, 1, 0, 0, 16, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0))
    pilot.send(M.MAVLink_mission_item_int_message(1, 1, 1, rel, 16, 0, 1, 0, 0, 0, 0, 0, 0, -5, 0))
    assert pilot.of_type("MISSION_ACK")[-1].type == M.MAV_MISSION_INVALID_PARAM7


def test_reposition_outside_the_fence_is_denied() -> None:
    pilot = _fenced(alt_max_m=100.0, radius_m=300.0)
    pilot.takeoff(5)
    home = pilot.sitl.config.home
    ack = pilot.command(M.MAV_CMD_DO_REPOSITION, -1, 1, 0, 0, home.lat_deg + 0.01, home.lon_deg, 10)
    assert ack.result == M.MAV_RESULT_DENIED
    assert "Fence" in pilot.statustexts()[-1]
    assert pilot.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 500).result != 0


def test_sys_status_reports_the_fence_as_arducopter_does() -> None:
    pilot = Pilot()
    pilot.run(1.5)
    status = pilot.latest["SYS_STATUS"]
    assert status.onboard_control_sensors_present & GEOFENCE
    assert status.onboard_control_sensors_health & GEOFENCE  # not breached: no "fence breach"
    assert not status.onboard_control_sensors_enabled & GEOFENCE  # FENCE_ENABLE 0 by default
    pilot = _fenced(action=0, avoid=0)  # report only: the breach shows in SYS_STATUS
    pilot.takeoff(5)
    for _ in range(24):
        pilot.send(_local_target(vel=(0, 0, -5)))
        pilot.run(0.5)
    status = pilot.latest["SYS_STATUS"]
    assert status.onboard_control_sensors_enabled & GEOFENCE
    assert not status.onboard_control_sensors_health & GEOFENCE
    assert pilot.mode() == 4  # still GUIDED: FENCE_ACTION 0 only reports


def test_velocity_streams_stop_short_of_the_fence_as_arducopters_avoidance() -> None:
    """AVOID_ENABLE on (ArduCopter's default): a climb at full rate and a stream asking for a
    million m/s outward both end inside the fence less FENCE_MARGIN, with no breach; the
    stream outward slides along the circle."""
    pilot = _fenced(alt_max_m=20.0, radius_m=50.0)
    pilot.takeoff(5)
    highest_m = farthest_m = 0.0
    for _ in range(40):
        pilot.send(_local_target(vel=(0, 0, -5)))
        pilot.run(0.5)
        highest_m = max(highest_m, pilot.alt_m())
    assert 17.0 < highest_m <= 18.0 + 0.05  # FENCE_ALT_MAX − FENCE_MARGIN
    for _ in range(60):
        pilot.send(_local_target(vel=(1e6, 2e5, 0)))
        pilot.run(0.5)
        n, e, _ = pilot.sitl.autopilot.state.pos_ned_m
        farthest_m = max(farthest_m, math.hypot(n, e))
    assert 45.0 < farthest_m <= 48.0 + 0.3  # FENCE_RADIUS − FENCE_MARGIN
    assert not any(t.startswith("Fence breached") for t in pilot.statustexts())
    assert pilot.mode() == 4  # still GUIDED


def test_at_the_fence_a_velocity_stream_slides_along_it() -> None:
    """AVOID_BEHAVE 0 (Copter's default): 20 m east of home, a stream due north ends at the
    circle's northern edge, not where its line meets the circle (43.6 m north, 20 m east)."""
    pilot = _fenced(alt_max_m=40.0, radius_m=50.0)
    pilot.takeoff(10)
    pilot.send(_local_target(pos=(0, 20, -10)))
    pilot.run(15.0)
    for _ in range(80):
        pilot.send(_local_target(vel=(8, 0, 0)))
        pilot.run(0.5)
    n, e, _ = pilot.sitl.autopilot.state.pos_ned_m
    assert math.hypot(n, e) <= 48.3 and n > 45.0
    assert e < 10.0  # slid along the circle toward where the stream points
    assert not any(t.startswith("Fence breached") for t in pilot.statustexts())


def test_taking_control_after_a_breach_gets_arducopters_manual_recovery() -> None:
    """Without avoidance, a stream breaches the fence and RTL flies; a ground station that
    switches back to GUIDED and streams on gets 10 s (\"Manual recovery started\"), then the
    backup fence 20 m beyond turns it back again, and 100 m out the fence gives up on RTL and
    lands: ArduCopter's AC_Fence, step by step."""
    pilot = _fenced(radius_m=50.0, avoid=0)
    pilot.takeoff(10)
    actions = []
    farthest_m = 0.0
    ap = pilot.sitl.autopilot
    for _ in range(240):  # 120 s of a client insisting
        if ap.mode != Mode.GUIDED:
            actions.append((pilot.sitl.now_ns / 1e9, int(ap.mode)))
            assert pilot.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
        pilot.send(_local_target(vel=(1e6, 0, 0)))
        pilot.run(0.5)
        n, e, _ = pilot.sitl.autopilot.state.pos_ned_m
        farthest_m = max(farthest_m, math.hypot(n, e))
    texts = pilot.statustexts()
    assert texts.count("Manual recovery started") >= 2 * len(actions)  # the action's, ours
    assert [mode for _, mode in actions][:1] == [RTL]
    # each new action waited out the 10 s of recovery after the last one
    assert all(b - a >= 10.0 for (a, _), (b, _) in itertools.pairwise(actions))
    assert LAND in [mode for _, mode in actions]  # given up: more than 100 m outside
