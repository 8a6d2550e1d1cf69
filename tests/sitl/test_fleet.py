"""Several built-in vehicles in one world (``uavtool.sitl.fleet``): one clock, homes on an
offset line, each its own MAVLink identity, and contact between vehicles a crash for both.

Stepped by the test (no sockets, no wall clock), so every time is vehicle time.
"""

from __future__ import annotations

import math
import socket

import pytest

from uavtool.errors import InputError, LinkError
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Prism, SitlConfig
from uavtool.sitl.fleet import (
    Fleet,
    OffsetLine,
    _swept_distance,  # its geometry, tested alone
    fleet_configs,
    line_homes,
    parse_offset_line,
    vehicle_seed,
)

from .pilot import Pilot

HOME = GeoPoint(-35.363261, 149.165230, 584.0)
POS_ONLY = 0b110111111000  # position target, no yaw


def _fleet(n: int, line: OffsetLine | None = None, **config: object) -> tuple[Fleet, list[Pilot]]:
    # No heartbeats from these pilots: no ground-station failsafe either.
    params = (("FS_GCS_ENABLE", 0.0), *config.pop("params", ()))  # type: ignore[misc]
    base = SitlConfig(endpoints=(), start_unix_us=0, params=params, **config)  # type: ignore[arg-type]
    fleet = Fleet(fleet_configs(base, line_homes(HOME, n, line or OffsetLine())))
    pilots = [Pilot(v, step=fleet.step) for v in fleet.vehicles]
    return fleet, pilots


def _go(pilot: Pilot, north: float, east: float, up: float) -> None:
    """A guided position target in the vehicle's own frame (around its own home)."""
    pilot.send(
        M.MAVLink_set_position_target_local_ned_message(
            0, pilot.target, 1, M.MAV_FRAME_LOCAL_NED, POS_ONLY,
            north, east, -up, 0, 0, 0, 0, 0, 0, 0, 0,
        )
    )  # fmt: skip


def _take_off_all(pilots: list[Pilot], alt_m: float) -> None:
    for p in pilots:
        p.run(0.2)
        assert p.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
        assert p.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        ack = p.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt_m)
        assert ack.result == M.MAV_RESULT_ACCEPTED
    pilots[0].run_until(
        lambda _p: all(q.sitl.autopilot.alt_rel_m() > alt_m - 0.3 for q in pilots),
        60,
        f"every vehicle at {alt_m} m",
    )


def test_homes_lie_on_the_offset_line() -> None:
    homes = line_homes(HOME, 4, OffsetLine(90.0, 10.0))
    assert homes[0] == HOME
    for i, home in enumerate(homes):
        east, north, up = enu_from_geo(HOME, home)
        assert east == pytest.approx(10.0 * i, abs=1e-3)
        assert north == pytest.approx(0.0, abs=1e-3)
        assert up == 0.0
    east, north, _ = enu_from_geo(HOME, line_homes(HOME, 2, OffsetLine(0.0, 25.0))[1])
    assert (east, north) == pytest.approx((0.0, 25.0), abs=1e-3)


@pytest.mark.parametrize("text", ["90", "a,b", "90,0", "90,-5", "nan,10", "1,2,3", "90,1e9"])
def test_a_bad_offset_line_is_refused(text: str) -> None:
    with pytest.raises(InputError, match="offset line"):
        parse_offset_line(text)


def test_the_first_vehicle_keeps_the_seed_and_no_two_share_one() -> None:
    assert vehicle_seed(7, 0) == 7
    seeds = {vehicle_seed(s, i) for s in range(20) for i in range(8)}
    assert len(seeds) == 20 * 8  # no vehicle of one flight draws another flight's stream


def test_each_vehicle_has_its_own_identity_and_all_share_one_clock() -> None:
    fleet, pilots = _fleet(3)
    assert fleet.sysids == (1, 2, 3)
    pilots[0].run(2.0)
    for i, p in enumerate(pilots):
        p.run(0.0)  # collect what it was sent while the first pilot stepped the world
        beats = p.of_type("HEARTBEAT")
        assert beats and {m.get_srcSystem() for m in beats} == {i + 1}
        assert p.sitl.now_ns == fleet.now_ns
    # Each reports its own home: 10 m apart along the line.
    east, _, _ = enu_from_geo(fleet.vehicles[0].config.home, fleet.vehicles[2].config.home)
    assert east == pytest.approx(20.0, abs=1e-3)
    # A command for vehicle 2 moves vehicle 2 only.
    assert pilots[1].set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
    assert [v.autopilot.mode.name for v in fleet.vehicles] == ["STABILIZE", "GUIDED", "STABILIZE"]


def test_vehicles_that_touch_both_crash() -> None:
    fleet, pilots = _fleet(2)
    _take_off_all(pilots, 10.0)
    _go(pilots[1], 0.0, -10.0, 10.0)  # vehicle 2 to where vehicle 1 hovers
    pilots[1].run_until(lambda _p: fleet.contacts != [], 30, "contact")
    pilots[1].run(1.0)
    assert all(v.crashed for v in fleet.vehicles)
    assert fleet.vehicles[0].crash_reason == "Crash: collision with vehicle 2"
    assert fleet.vehicles[1].crash_reason == "Crash: collision with vehicle 1"
    assert fleet.approach.gap_m <= 0.0 and fleet.approach.sysids == (1, 2)
    assert "Crash: collision with vehicle 1" in pilots[1].statustexts()


def test_passing_close_is_measured_not_a_crash() -> None:
    fleet, pilots = _fleet(2)
    _take_off_all(pilots, 10.0)
    # Vehicle 2 flies past vehicle 1 2 m to its north, at the same height.
    _go(pilots[1], 2.0, 0.0, 10.0)
    pilots[1].run(5.0)
    _go(pilots[1], 2.0, -30.0, 10.0)
    pilots[1].run_until(
        lambda p: p.sitl.autopilot.vehicle.state.pos_ned_m[1] < -29.0, 60, "passing"
    )
    assert not any(v.crashed for v in fleet.vehicles)
    # Two bodies of 0.4 m: a gap of about 2 - 0.8 m, less what the vehicles sway.
    assert 0.8 < fleet.approach.gap_m < 1.3
    assert fleet.approach.sysids == (1, 2)


def test_vehicles_meeting_head_on_both_crash() -> None:
    fleet, pilots = _fleet(2, OffsetLine(90.0, 60.0))
    _take_off_all(pilots, 10.0)
    _go(pilots[0], 0.35, 60.0, 10.0)
    _go(pilots[1], -0.35, -60.0, 10.0)
    pilots[0].run_until(lambda _p: fleet.contacts != [], 30, "contact")
    assert all(v.crashed for v in fleet.vehicles)


def test_two_points_that_cross_between_two_steps_are_seen_to_meet() -> None:
    # 20 m/s each, head-on, 0.5 m apart sideways: 0.8 m closer per 50 Hz step, so the two
    # steps either side of the crossing see them 0.9 m apart; in between they pass at 0.5 m.
    a0, a1 = (-0.4, 0.0, 10.0), (0.4, 0.0, 10.0)
    b0, b1 = (0.4, 0.5, 10.0), (-0.4, 0.5, 10.0)
    assert math.dist(a0, b0) > 0.8 and math.dist(a1, b1) > 0.8
    assert _swept_distance(a0, a1, b0, b1) == pytest.approx(0.5)
    assert _swept_distance(a0, a0, b0, b0) == pytest.approx(math.dist(a0, b0))  # standing


def test_two_vehicles_on_the_ground_are_not_judged() -> None:
    fleet, pilots = _fleet(2, OffsetLine(90.0, 1.0))
    pilots[0].run(1.0)
    assert fleet.approach.gap_m == math.inf and not fleet.contacts


def test_a_home_inside_a_building_is_refused() -> None:
    box = Prism("shed", ((15.0, -5.0), (25.0, -5.0), (25.0, 5.0), (15.0, 5.0)), 0.0, 6.0)
    base = SitlConfig(endpoints=(), start_unix_us=0)
    homes = line_homes(HOME, 3, OffsetLine())

    def obstacles(home: GeoPoint) -> tuple[Prism, ...]:
        east, north, _ = enu_from_geo(home, HOME)
        shifted = tuple((e + east, n + north) for e, n in box.footprint_en_m)
        return (Prism(box.name, shifted, box.base_m, box.top_m),)

    with pytest.raises(InputError, match=r"vehicle 3's home .* is in building 'shed'"):
        Fleet(fleet_configs(base, homes, obstacles_for=obstacles))


def test_vehicles_on_one_spot_are_refused() -> None:
    base = SitlConfig(endpoints=(), start_unix_us=0)
    with pytest.raises(InputError, match=r"vehicles 1 and 2 stand 0\.00 m apart"):
        Fleet(fleet_configs(base, (HOME, HOME)))


def test_a_fleet_of_one_flies_as_one_vehicle() -> None:
    _, (in_fleet,) = _fleet(1)
    alone = Pilot(start_unix_us=0, params=(("FS_GCS_ENABLE", 0.0),))
    for p in (in_fleet, alone):
        p.takeoff(5.0)
        _go(p, 10.0, 5.0, 8.0)
        p.run(6.0)
    a = in_fleet.sitl.autopilot.vehicle.state.pos_ned_m
    b = alone.sitl.autopilot.vehicle.state.pos_ned_m
    assert list(a) == list(b)
    assert in_fleet.sitl.now_ns == alone.sitl.now_ns


def test_a_port_in_use_fails_the_fleet_cleanly() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        base = SitlConfig(endpoints=(f"tcpin:127.0.0.1:{port - 10}",), start_unix_us=0)
        with pytest.raises(LinkError, match=f"port {port} is in use"):
            Fleet(fleet_configs(base, line_homes(HOME, 2, OffsetLine())))
