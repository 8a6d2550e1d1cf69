"""Collisions are real: a vehicle that touches a building or hits the ground hard crashes, one
that passes by measures its clearance, and a take-off under an overhang is refused.

Flown in lockstep (``LockstepTransport`` + ``VehicleLink``, as ``uavtool fly`` does), so every
time below is vehicle time and every run is the same.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.link import VehicleLink
from uavtool.mavlink import mavlink as M
from uavtool.mavlink.dialect import COPTER_MODES
from uavtool.sitl import Mode, Prism, Sitl, SitlConfig
from uavtool.sitl.crash import CLEARANCE_RESOLUTION_M
from uavtool.sitl.lockstep import LockstepTransport
from uavtool.sitl.obstacles import prism_distance_m
from uavtool.world import load_scene
from uavtool.world.obstacles import scene_obstacles

POS_ONLY = 0b110111111000  # position target, no yaw
VEL_ONLY = 0b110111000111
FORCE = 21196
RADIUS_M = 0.4


def _square(name: str, east: tuple[float, float], north: tuple[float, float], base: float,
            top: float) -> Prism:  # fmt: skip
    (e0, e1), (n0, n1) = east, north
    return Prism(name, ((e0, n0), (e1, n0), (e1, n1), (e0, n1)), base, top)


class Pilot:
    """A ground station flying an in-process vehicle in lockstep; ``messages`` keeps all."""

    def __init__(self, *obstacles: Prism) -> None:
        config = SitlConfig(endpoints=(), obstacles=obstacles, start_unix_us=0)
        self.transport = LockstepTransport(config)
        self.vehicle: Sitl = self.transport.vehicle
        self.link = VehicleLink(self.transport, clock=self.transport.clock)
        self.messages: list[Any] = []
        self._cursor = 0
        self._stream: tuple[float, float, float] | None = None  # a velocity sent at 2 Hz
        self._streamed_s = 0.0
        self.link.wait_vehicle(10.0)

    def close(self) -> None:
        self.link.close()

    def now_s(self) -> float:
        return self.transport.clock()

    def wait_for(
        self, kind: str, cond: Callable[[Any], bool] | None = None, timeout_s: float = 30.0
    ) -> Any:
        """The next matching message after the last one waited for (vehicle time)."""
        deadline = self.now_s() + timeout_s
        while True:
            while self._cursor < len(self.messages):
                msg = self.messages[self._cursor]
                self._cursor += 1
                if msg.get_type() == kind and (cond is None or cond(msg)):
                    return msg
            if self.now_s() > deadline:
                raise AssertionError(f"no {kind} within {timeout_s} s of vehicle time")
            self._keep_streaming()
            self.messages += self.link.poll(0.1)

    def wait_until(self, cond: Callable[[], bool], timeout_s: float = 60.0, what: str = "") -> None:
        deadline = self.now_s() + timeout_s
        while not cond():
            if self.now_s() > deadline:
                raise AssertionError(f"timed out waiting for {what}")
            self._keep_streaming()
            self.messages += self.link.poll(0.1)

    def fly_for(self, seconds: float) -> None:
        end = self.now_s() + seconds
        self.wait_until(lambda: self.now_s() >= end, seconds + 1.0)

    def command(self, command: int, *params: float) -> Any:
        self.link.command_long(command, *params)
        return self.wait_for("COMMAND_ACK", lambda m: m.command == command, 5.0)

    def set_mode(self, name: str) -> Any:
        return self.command(M.MAV_CMD_DO_SET_MODE, 1, COPTER_MODES[name])

    def takeoff(self, alt_m: float) -> None:
        assert self.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
        assert self.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        ack = self.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt_m)
        assert ack.result == M.MAV_RESULT_ACCEPTED
        self.wait_until(lambda: self.alt_m() > alt_m - 0.05, what=f"take-off to {alt_m} m")

    def goto(self, north_m: float, east_m: float, alt_m: float) -> None:
        self.link.send(
            M.MAVLink_set_position_target_local_ned_message(
                0, 1, 1, M.MAV_FRAME_LOCAL_NED, POS_ONLY, north_m, east_m, -alt_m,
                0, 0, 0, 0, 0, 0, 0, 0,
            )
        )  # fmt: skip

    def velocity(self, vn: float, ve: float, vd: float) -> None:
        """Fly at this velocity, sent again every 0.5 s as a companion computer streams it
        (ArduCopter stops after 3 s without one)."""
        self._stream, self._streamed_s = (vn, ve, vd), self.now_s()
        self.link.send(
            M.MAVLink_set_position_target_local_ned_message(
                0, 1, 1, M.MAV_FRAME_LOCAL_NED, VEL_ONLY, 0, 0, 0, vn, ve, vd, 0, 0, 0, 0, 0
            )
        )

    def _keep_streaming(self) -> None:
        if self._stream is not None and self.now_s() - self._streamed_s >= 0.5:
            self.velocity(*self._stream)

    def set_param(self, name: str, value: float) -> None:
        self.link.send(
            M.MAVLink_param_set_message(1, 1, name.encode(), value, M.MAV_PARAM_TYPE_REAL32)
        )
        self.wait_for("PARAM_VALUE", lambda m: m.param_id == name, 5.0)

    def alt_m(self) -> float:
        return float(self.link.state.position.relative_alt) / 1000.0

    def local(self) -> tuple[float, float, float]:
        """The latest LOCAL_POSITION_NED: (north, east, down) in metres."""
        m = next(m for m in reversed(self.messages) if m.get_type() == "LOCAL_POSITION_NED")
        return m.x, m.y, m.z

    def texts(self) -> list[tuple[int, str]]:
        return list(self.link.state.statustext)

    def armed(self) -> bool:
        return bool(self.link.state.heartbeat.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)


@pytest.fixture
def pilot_factory() -> Any:
    pilots: list[Pilot] = []

    def make(*obstacles: Prism) -> Pilot:
        pilots.append(Pilot(*obstacles))
        return pilots[-1]

    yield make
    for p in pilots:
        p.close()


def test_flying_into_a_building_crashes(pilot_factory: Callable[..., Pilot]) -> None:
    # A 10 m tall block across the path, its west wall 20 m east of home.
    pilot = pilot_factory(_square("red", (20.0, 30.0), (-5.0, 5.0), 0.0, 10.0))
    pilot.takeoff(5.0)
    pilot.goto(0.0, 40.0, 5.0)
    crash = pilot.wait_for("STATUSTEXT", lambda m: m.text.startswith("Crash:"))
    crashed_at_s = pilot.now_s()
    assert crash.text == "Crash: collision with building 'red'"
    assert crash.severity == M.MAV_SEVERITY_EMERGENCY
    sitl = pilot.vehicle
    assert sitl.crashed
    assert sitl.crash_reason == crash.text
    assert sitl.closest_obstacle == "red"
    # Detected on the first 50 Hz step inside the body radius: ≤ one step (10 m/s) deep.
    assert -0.2 - 1e-6 <= sitl.closest_clearance_m < 0.0

    # Motors off, disarmed; it falls 5 m under gravity (√(2·5/g) ≈ 1.0 s) where it hit.
    pilot.wait_until(lambda: pilot.alt_m() <= 0.0, 3.0, "the wreck on the ground")
    assert pilot.now_s() - crashed_at_s == pytest.approx(math.sqrt(2 * 5.0 / 9.80665), abs=0.15)
    hb = pilot.wait_for("HEARTBEAT", lambda m: not m.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)
    assert hb.system_status == M.MAV_STATE_EMERGENCY
    pilot.fly_for(0.2)
    north, east, down = pilot.local()
    assert (north, down) == pytest.approx((0.0, 0.0), abs=1e-3)
    assert 20.0 - RADIUS_M - 0.2 <= east <= 20.0 - RADIUS_M + 0.2

    # It stays a wreck: arming (even forced) and taking off are refused, status stays EMERGENCY.
    assert pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_FAILED
    ack = pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1, FORCE)
    assert ack.result == M.MAV_RESULT_FAILED
    ack = pilot.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, 5.0)
    assert ack.result == M.MAV_RESULT_FAILED
    pilot.fly_for(3.0)
    texts = [text for _, text in pilot.texts()]
    assert texts.count("Arm: vehicle crashed; reboot to arm") == 2
    assert "Takeoff: vehicle crashed" in texts
    assert not pilot.armed()
    assert pilot.wait_for("HEARTBEAT").system_status == M.MAV_STATE_EMERGENCY
    status = pilot.wait_for("SYS_STATUS")
    assert not status.onboard_control_sensors_health & M.MAV_SYS_STATUS_PREARM_CHECK
    assert pilot.wait_for("EXTENDED_SYS_STATE").landed_state == M.MAV_LANDED_STATE_ON_GROUND


def test_passing_a_roof_edge_measures_the_clearance(pilot_factory: Callable[..., Pilot]) -> None:
    # A 4 m tall block whose north wall is 2 m south of the path, flown at 7 m: the nearest
    # point is the roof's north edge, hypot(2, 3) m from the path.
    pilot = pilot_factory(_square("low", (20.0, 30.0), (-10.0, -2.0), 0.0, 4.0))
    pilot.takeoff(7.0)
    pilot.goto(0.0, 40.0, 7.0)
    pilot.wait_until(lambda: pilot.local()[1] > 39.9, 30.0, "the far side")
    pilot.set_mode("LAND")
    pilot.wait_until(lambda: not pilot.armed(), 30.0, "landed and disarmed")
    sitl = pilot.vehicle
    assert not sitl.crashed
    assert sitl.closest_obstacle == "low"
    expected = math.hypot(2.0, 3.0) - RADIUS_M
    # within the few centimetres the vehicle's height moves as it leans to speed up and brake
    assert sitl.closest_clearance_m == pytest.approx(expected, abs=0.06)
    texts = [text for _, text in pilot.texts()]
    assert "Land complete: disarming" in texts
    assert not any(t.startswith("Crash") for t in texts)
    assert pilot.link.state.heartbeat.system_status == M.MAV_STATE_STANDBY
    pilot.set_mode("GUIDED")  # LAND is not armable
    assert pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED


def test_no_obstacles_no_clearance(pilot_factory: Callable[..., Pilot]) -> None:
    pilot = pilot_factory()
    pilot.takeoff(3.0)
    assert pilot.vehicle.closest_clearance_m == math.inf
    assert pilot.vehicle.closest_obstacle == ""


@pytest.mark.parametrize("mode", ["LAND", "RTL"])
def test_normal_landings_among_buildings_do_not_crash(
    pilot_factory: Callable[..., Pilot], mode: str
) -> None:
    pilot = pilot_factory(*scene_obstacles(load_scene("paper")))
    pilot.takeoff(10.0)
    pilot.goto(-16.0, -3.0, 10.0)  # between blue and red, over the open ground south of home
    pilot.wait_until(lambda: pilot.local()[0] < -15.9, 30.0, "the landing spot")
    assert pilot.set_mode(mode).result == M.MAV_RESULT_ACCEPTED
    pilot.wait_until(lambda: not pilot.armed(), 90.0, "landed and disarmed")
    assert not pilot.vehicle.crashed
    assert pilot.vehicle.closest_clearance_m > 1.0
    assert pilot.link.state.heartbeat.system_status == M.MAV_STATE_STANDBY


def test_hard_vertical_impact_crashes(pilot_factory: Callable[..., Pilot]) -> None:
    pilot = pilot_factory()
    pilot.takeoff(20.0)
    pilot.set_param("WPNAV_SPEED_DN", 500)  # let it dive at 5 m/s
    pilot.set_param("WPNAV_ACCEL_Z", 500)  # and get there quickly
    pilot.velocity(0.0, 0.0, 5.0)
    crash = pilot.wait_for("STATUSTEXT", lambda m: m.text.startswith("Crash:"), 10.0)
    speed = float(crash.text.removeprefix("Crash: hit the ground at ").removesuffix(" m/s"))
    assert 3.0 < speed <= 5.0
    assert crash.severity == M.MAV_SEVERITY_EMERGENCY
    assert pilot.vehicle.crashed
    assert pilot.wait_for("HEARTBEAT").system_status == M.MAV_STATE_EMERGENCY
    assert pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_FAILED


def test_touching_down_sideways_crashes(pilot_factory: Callable[..., Pilot]) -> None:
    pilot = pilot_factory()
    pilot.takeoff(2.0)
    pilot.velocity(5.0, 0.0, 1.0)  # 5 m/s north while sinking at 1 m/s: it tips over
    crash = pilot.wait_for("STATUSTEXT", lambda m: m.text.startswith("Crash:"), 10.0)
    assert crash.text.startswith("Crash: hit the ground at ")
    assert pilot.vehicle.crashed


def test_a_gentle_descent_in_guided_does_not_crash(pilot_factory: Callable[..., Pilot]) -> None:
    pilot = pilot_factory()
    pilot.takeoff(5.0)
    pilot.velocity(0.0, 0.0, 1.5)  # the default WPNAV_SPEED_DN
    pilot.wait_until(lambda: pilot.alt_m() <= 0.0, 10.0, "touchdown")
    pilot.fly_for(1.0)
    assert not pilot.vehicle.crashed


def test_takeoff_under_an_overhang_is_denied(pilot_factory: Callable[..., Pilot]) -> None:
    # A slab 6-8 m up, right over home (a carport roof, a bridge).
    pilot = pilot_factory(_square("bridge", (-3.0, 3.0), (-3.0, 3.0), 6.0, 8.0))
    assert pilot.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
    assert pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
    for alt_m in (10.0, 5.7):  # through it; into it with the body's top (5.7 + 0.4 > 6)
        ack = pilot.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt_m)
        assert ack.result == M.MAV_RESULT_DENIED
    texts = [text for _, text in pilot.texts()]
    assert texts.count("Takeoff: obstacle above at 6.0 m") == 2
    assert pilot.alt_m() == 0.0
    # Below it there is room: 5 m + 0.4 m leaves 0.6 m under the slab.
    ack = pilot.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, 5.0)
    assert ack.result == M.MAV_RESULT_ACCEPTED
    pilot.wait_until(lambda: pilot.alt_m() > 4.95, 10.0, "take-off to 5 m")
    pilot.fly_for(5.0)
    assert not pilot.vehicle.crashed
    # less the couple of centimetres the climb overshoots 5 m by
    assert pilot.vehicle.closest_clearance_m == pytest.approx(0.6, abs=0.04)


def test_takeoff_against_a_wall_is_denied(pilot_factory: Callable[..., Pilot]) -> None:
    pilot = pilot_factory(_square("wall", (0.2, 1.0), (-5.0, 5.0), 0.0, 10.0))
    pilot.set_mode("GUIDED")
    pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    ack = pilot.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, 5.0)
    assert ack.result == M.MAV_RESULT_DENIED
    assert pilot.texts()[-1][1] == "Takeoff: obstacle 'wall' within 0.2 m"


def test_clearance_is_the_least_over_every_step() -> None:
    """The record skips geometry while the vehicle is provably far; it still equals the
    least clearance over all 50 Hz steps, to its resolution, on a flight among buildings."""
    prisms = scene_obstacles(load_scene("paper"))
    sitl = Sitl(SitlConfig(endpoints=(), obstacles=prisms, start_unix_us=0))
    ap = sitl.autopilot
    least = math.inf
    nearest = ""

    def run(seconds: float) -> None:
        nonlocal least, nearest
        for _ in range(round(seconds * 50)):
            sitl.step()
            if ap.armed and not ap.on_ground:
                n, e, d = ap.state.pos_ned_m
                for p in prisms:
                    c = prism_distance_m(p, e, n, -d) - RADIUS_M
                    if c < least:
                        least, nearest = c, p.name

    ap.set_mode(Mode.GUIDED)
    assert ap.arm(force=False).ok
    assert ap.takeoff(8.0).ok
    run(8)
    # Weave between the buildings: over blue's roof, past red's corner, between the others.
    for target in [(-8.0, -11.0, -6.0), (-6.0, 3.0, -8.0), (3.0, -5.0, -8.0), (8.0, 6.0, -9.0)]:
        assert ap.guided_position(target).ok
        run(12)
    ap.set_mode(Mode.RTL)
    run(60)
    assert not ap.crashed
    assert not ap.armed
    assert least < 3.0  # it did pass close
    assert least <= ap.collisions.closest_clearance_m <= least + CLEARANCE_RESOLUTION_M
    assert ap.collisions.closest_obstacle == nearest
    sitl.close()


def test_cli_sitl_with_a_scene() -> None:
    result = CliRunner().invoke(
        cli,
        ["sitl", "--scene", "paper", "--duration", "1", "--speedup", "1000",
         "--endpoint", "tcpin:127.0.0.1:0"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "scene 'paper' (9 obstacles)" in result.output
    assert "stopped at sim time 1.0 s" in result.output


def test_cli_sitl_with_a_missing_scene() -> None:
    result = CliRunner().invoke(cli, ["sitl", "--scene", "/nonexistent.yaml", "--duration", "1"])
    assert result.exit_code == 2
    assert "no such scene file" in result.output
