"""The built-in vehicle flies through forces: the air, its thrust, lean and drag, and the
ground decide where it goes; wind and gusts act on the air, never on its position."""

from __future__ import annotations

import math
import random

import pytest

from uavtool.sitl.frame import GRAVITY_MSS, Frame, air_density_kgm3, airframe
from uavtool.sitl.physics import Multicopter, Target
from uavtool.sitl.wind import Wind, WindParams

DT_S = 0.02
HOME_ALT_M = 584.0  # ArduPilot SITL's default home, where the frame's reference flights were


def _vehicle(
    wind: WindParams | None = None, *, seed: int = 0, alt_m: float = HOME_ALT_M
) -> Multicopter:
    m = Multicopter(rng=random.Random(seed), home_alt_amsl_m=alt_m)
    if wind is not None:
        m.air.set_params(wind)
        m.air = Wind(random.Random(seed), wind)  # the wind blows from boot
    m.arm()
    return m


def _run(m: Multicopter, seconds: float) -> None:
    for _ in range(round(seconds / DT_S)):
        m.step(DT_S)


def _hover(m: Multicopter, alt_m: float = 45.0, settle_s: float = 40.0) -> None:
    _run(m, 3.0)  # the arming delay and the spool-up
    m.set_target(Target(pos_ned_m=(0.0, 0.0, -alt_m)))
    _run(m, settle_s)


def _lean_deg(m: Multicopter) -> float:
    ln, le = m.state.lean_ne
    return math.degrees(math.asin(math.hypot(ln, le)))


def test_calm_hover_holds_with_the_weight_and_no_lean() -> None:
    m = _vehicle()
    _hover(m)
    s = m.state
    assert s.pos_ned_m == pytest.approx([0.0, 0.0, -45.0], abs=0.01)
    assert s.thrust_n == pytest.approx(m.body.weight_n, rel=1e-3)
    assert _lean_deg(m) < 0.01
    # hover throttle at the frame's reference altitude: its MOT_THST_HOVER
    assert s.throttle == pytest.approx(Frame().hover_throttle, rel=0.01)


def test_a_steady_wind_is_held_by_leaning_into_it_as_drag_demands() -> None:
    # 8 m/s from the west above SIM_WIND_T_ALT: the vehicle stays put, leaning east-to-west.
    m = _vehicle(WindParams(speed_ms=8.0, from_deg=270.0))
    _hover(m, alt_m=85.0, settle_s=60.0)
    s = m.state
    assert math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 0.05  # the integrator learned the wind
    assert s.lean_ne[1] < 0.0 and abs(s.lean_ne[0]) < 1e-3  # thrust tilted west, into it
    # ArduCopter's SITL flying the same frame leans 22.5° (benchmarks/bench_dynamics.py)
    assert 19.0 < _lean_deg(m) < 25.0
    assert s.thrust_n > m.body.weight_n  # it carries the weight and pushes against the drag


@pytest.mark.parametrize("speed_ms", [0.0, 4.0, 8.0, 12.0])
def test_more_wind_more_lean_and_more_power(speed_ms: float) -> None:
    m = _vehicle(WindParams(speed_ms=speed_ms, from_deg=0.0))
    _hover(m, alt_m=70.0)
    lean = _lean_deg(m)
    calm = _vehicle()
    _hover(calm, alt_m=70.0)
    if speed_ms == 0.0:
        assert lean < 0.01
    else:
        assert lean > speed_ms  # degrees: a few per m/s at these speeds
        assert m.state.thrust_n > calm.state.thrust_n  # the battery pays for the wind


def test_a_wind_stronger_than_the_lean_can_hold_blows_the_vehicle_away() -> None:
    m = _vehicle(WindParams(speed_ms=16.0, from_deg=270.0))
    _hover(m, alt_m=70.0, settle_s=20.0)
    east_0 = m.state.pos_ned_m[1]
    _run(m, 10.0)
    assert m.state.pos_ned_m[1] - east_0 > 10.0  # drifting east, downwind
    assert _lean_deg(m) == pytest.approx(30.0, abs=0.1)  # at ANGLE_MAX, into the wind
    assert m.state.lean_ne[1] < 0.0


def test_on_the_ground_gusts_do_not_slide_it_and_take_off_works() -> None:
    m = _vehicle(WindParams(speed_ms=10.0, from_deg=270.0, turbulence_ms=2.0))
    _run(m, 30.0)  # armed, idling in the wind
    assert m.state.pos_ned_m == [0.0, 0.0, 0.0]
    assert m.state.landed
    m.set_target(Target(pos_ned_m=(0.0, 0.0, -45.0)))
    _run(m, 40.0)
    s = m.state
    assert not s.on_ground
    assert s.pos_ned_m[2] == pytest.approx(-45.0, abs=0.5)
    assert math.hypot(s.pos_ned_m[0], s.pos_ned_m[1]) < 2.0  # blown about, and back


def test_the_take_off_waits_for_arming_delay_spool_up_and_the_throttle_ramp() -> None:
    m = _vehicle()
    m.set_target(Target(pos_ned_m=(0.0, 0.0, -10.0)))
    left_ground_s = None
    for i in range(round(10.0 / DT_S)):
        m.step(DT_S)
        if left_ground_s is None and m.state.pos_ned_m[2] < -0.01:
            left_ground_s = (i + 1) * DT_S
    # 2 s arming delay, 0.5 s spool-up, then the throttle passes the hover (0.39) at 0.5/s,
    # and the motors and the growing excess of thrust need a moment to lift it by a centimetre
    assert 2.0 + 0.5 + 0.39 / 0.5 < left_ground_s < 2.0 + 0.5 + 0.39 / 0.5 + 0.35


def test_motors_off_in_the_air_it_falls() -> None:
    m = _vehicle()
    _hover(m, alt_m=20.0)
    m.disarm()
    m.state.thrust_n = 0.0
    falling = 0.0
    for _ in range(round(3.0 / DT_S)):
        m.step(DT_S)
        if m.touchdown is not None:
            falling = m.touchdown.vel_ned_ms[2]
    assert m.state.on_ground
    # falling 20 m: slower than in a vacuum (√(2 g h)), its drag near its terminal speed
    # (√(weight / drag area) ≈ 17 m/s)
    terminal = math.sqrt(m.body.weight_n / m.body.drag_area_n_per_ms2)
    assert 0.7 * terminal < falling < min(terminal, math.sqrt(2 * GRAVITY_MSS * 20.0))


def test_gusts_move_the_air_and_the_vehicle_only_through_drag() -> None:
    m = _vehicle(WindParams(speed_ms=5.0, from_deg=90.0, turbulence_ms=3.0))
    _hover(m, alt_m=50.0, settle_s=20.0)
    worst_jump = 0.0
    prev = list(m.state.pos_ned_m)
    airs = []
    for _ in range(round(20.0 / DT_S)):
        m.step(DT_S)
        pos = m.state.pos_ned_m
        airs.append(m.air.ned_ms)
        step = math.dist(pos, prev)
        worst_jump = max(worst_jump, step - math.hypot(*m.state.vel_ned_ms) * DT_S)
        prev = list(pos)
    assert worst_jump < 1e-9  # the position only ever moves with the velocity
    gust_n = [a[0] for a in airs]
    assert max(gust_n) - min(gust_n) > 1.0  # the air itself is gusty
    assert math.hypot(m.state.pos_ned_m[0], m.state.pos_ned_m[1]) < 0.5  # the vehicle holds


def test_the_same_seed_flies_the_same_gusts() -> None:
    wind = WindParams(speed_ms=6.0, from_deg=200.0, turbulence_ms=2.0)
    a, b, c = _vehicle(wind, seed=3), _vehicle(wind, seed=3), _vehicle(wind, seed=4)
    for m in (a, b, c):
        _hover(m, alt_m=30.0, settle_s=15.0)
    assert a.state.pos_ned_m == b.state.pos_ned_m
    assert a.state.pos_ned_m != c.state.pos_ned_m


def test_wind_grows_with_height_as_sim_wind_t_says() -> None:
    air = Wind(random.Random(0), WindParams(speed_ms=10.0, from_deg=0.0))
    assert air.step(60.0, airborne=True, dt_s=DT_S)[0] == pytest.approx(-10.0)
    assert air.step(15.0, airborne=True, dt_s=DT_S)[0] == pytest.approx(-5.0)  # √(15/60)
    assert air.step(0.0, airborne=False, dt_s=DT_S) == (0.0, 0.0, 0.0)
    flat = Wind(random.Random(0), WindParams(speed_ms=10.0, from_deg=90.0, profile=1))
    assert flat.step(1.0, airborne=True, dt_s=DT_S)[1] == pytest.approx(-10.0)  # from the east


def test_a_changed_wind_takes_effect_over_sim_wind_tc() -> None:
    air = Wind(random.Random(0), WindParams())
    air.set_params(WindParams(speed_ms=10.0, from_deg=0.0, profile=1, change_tc_s=5.0))
    speeds = [-air.step(100.0, airborne=True, dt_s=DT_S)[0] for _ in range(round(10 / DT_S))]
    assert 0.0 < speeds[0] < 1.0
    assert 5.0 < speeds[round(1.0 / DT_S)] < 9.5
    assert speeds[-1] == 10.0


def test_turbulence_is_as_strong_as_ardupilots_seen_over_a_step() -> None:
    air = Wind(random.Random(1), WindParams(turbulence_ms=2.0))
    samples = [air.step(100.0, airborne=True, dt_s=DT_S) for _ in range(50_000)]
    n = [s[0] for s in samples]
    d = [s[2] for s in samples]
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))  # noqa: E731
    assert rms(n) == pytest.approx(2.0 * 1.005 / math.sqrt(2 * 1200 * DT_S), rel=0.05)
    assert rms(d) == pytest.approx(2.0, rel=0.1)


def test_thin_air_needs_more_throttle() -> None:
    low, high = _vehicle(alt_m=0.0), _vehicle(alt_m=3000.0)
    for m in (low, high):
        _hover(m, alt_m=20.0, settle_s=20.0)
    assert high.state.throttle > low.state.throttle * 1.2
    assert air_density_kgm3(3000.0) == pytest.approx(0.909, abs=0.005)  # ISA


def test_the_frame_flies_its_reference_flight() -> None:
    """At the frame's reference speed and air density, level flight needs its reference
    lean: the drag model reproduces the measurement it was built from."""
    frame = Frame()
    m = Multicopter(home_alt_amsl_m=frame.ref_alt_m)
    m.arm()
    _run(m, 3.0)
    m.set_target(Target(pos_ned_m=(0.0, 0.0, -60.0)))
    _run(m, 30.0)
    # the air moving past at the reference speed (profile 1: the same at any height)
    m.air = Wind(random.Random(0), WindParams(speed_ms=frame.ref_speed_ms, profile=1))
    m.limits.lean_max_deg = 60.0
    _run(m, 40.0)
    assert _lean_deg(m) == pytest.approx(frame.ref_angle_deg, abs=3.0)
    body = airframe(frame, density_kgm3=air_density_kgm3(frame.ref_alt_m))
    assert body.thrust_max_n == pytest.approx(body.weight_n / frame.hover_throttle)


def test_a_frame_that_cannot_fly_is_refused() -> None:
    with pytest.raises(ValueError, match="cannot fly"):
        airframe(Frame(hover_throttle=0.0), density_kgm3=1.2)


def test_a_ground_station_sees_the_vehicle_lean_into_the_wind() -> None:
    """Over a real socket (as MAVProxy, QGroundControl or MAVSDK see it), the wall-paced
    vehicle of ``uavtool sitl --wind 8,270`` holds its place leaning west, into the wind."""
    from tests.sitl.client import Client
    from uavtool.sitl import Sitl, SitlConfig

    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0",), speedup=40, wind_speed_ms=8.0, wind_dir_deg=270.0
    )
    with Sitl(config) as sitl:
        c = Client.tcp(sitl.ports[0])
        c.takeoff(70)
        c.wait_until(lambda cl: cl.boot_s() > 40.0, timeout=60, what="40 s of flight")
        att, pos = c.latest["ATTITUDE"], c.latest["LOCAL_POSITION_NED"]
        heading = math.radians(c.latest["VFR_HUD"].heading)
        # the thrust vector tilts west: rotate roll and pitch back into north and east
        west = math.sin(att.roll) * math.cos(heading) - math.sin(att.pitch) * math.sin(heading)
        assert west < -math.sin(math.radians(10.0))
        assert math.hypot(pos.x, pos.y) < 1.0
        c.close()
