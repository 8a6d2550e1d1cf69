"""The PX4 adapter: its modes, the GUIDED it emulates, every mission command as PX4 takes it
(checked on the frames it puts on the wire), and PX4's parameter names in the hints."""

from __future__ import annotations

import math
from typing import Any

import pytest

from tests.autopilot.fake_px4 import FakePX4, link_to
from uavtool.autopilot import PX4, ArduPilot, GenericMAVLink, for_vehicle
from uavtool.autopilot.px4 import px4_mode_name
from uavtool.errors import ParamError
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Arm, GoTo, SetGimbal, SetMode, Takeoff
from uavtool.mission.base import Envelope
from uavtool.runner.params import set_vehicle_params
from uavtool.runner.preflight import PreflightError, check_fence, check_gimbal, param_reader

HOME = GeoPoint(47.397743, 8.545597, 499.4)  # HOME_POSITION's altitude; the vehicle says 500.7


def _heartbeat(main: int, sub: int = 0) -> Any:
    return M.MAVLink_heartbeat_message(2, M.MAV_AUTOPILOT_PX4, 1, (main << 16) | (sub << 24), 3, 3)


@pytest.mark.parametrize(
    ("autopilot", "kind"),
    [(M.MAV_AUTOPILOT_PX4, PX4), (M.MAV_AUTOPILOT_ARDUPILOTMEGA, ArduPilot),
     (M.MAV_AUTOPILOT_GENERIC, GenericMAVLink)],
)  # fmt: skip
def test_the_adapter_follows_the_heartbeat(autopilot: int, kind: type) -> None:
    hb = M.MAVLink_heartbeat_message(2, autopilot, 1, 0, 3, 3)
    assert type(for_vehicle(hb)) is kind


def test_px4_mode_names_are_px4s_own() -> None:
    assert px4_mode_name(4, 3) == "AUTO.LOITER"
    assert px4_mode_name(4, 5) == "AUTO.RTL"
    assert px4_mode_name(6, 0) == "OFFBOARD"
    assert px4_mode_name(3, 1) == "POSCTL.ORBIT"
    assert px4_mode_name(4, 4) == "AUTO.MISSION"
    assert px4_mode_name(42, 0) == "MODE42"


def test_guided_is_emulated_and_any_other_mode_ends_it() -> None:
    px4, fake = PX4(), FakePX4({})
    link = link_to(fake)
    assert px4.mission_mode(_heartbeat(4, 3)) == "AUTO.LOITER"  # Hold, before GUIDED is asked
    px4.send(link, SetMode(1, "GUIDED"), HOME)
    assert px4.mission_mode(_heartbeat(3)) == "POSCTL"  # not switched yet: still the old mode
    assert px4.mission_mode(_heartbeat(4, 3)) == "GUIDED"
    assert px4.mission_mode(_heartbeat(4, 2)) == "GUIDED"  # the take-off it was told to make
    px4.send(link, SetMode(2, "RTL"), HOME)
    assert px4.mission_mode(_heartbeat(4, 3)) == "GUIDED"  # the switch is not shown yet
    assert px4.mission_mode(_heartbeat(4, 5)) == "RTL"
    assert px4.mission_mode(_heartbeat(4, 3)) == "AUTO.LOITER"  # Hold after landing: not ours
    px4.send(link, SetMode(3, "GUIDED"), HOME)
    assert px4.mission_mode(_heartbeat(4, 3)) == "GUIDED"
    assert px4.mission_mode(_heartbeat(3)) == "POSCTL"  # a pilot took over …
    assert px4.mission_mode(_heartbeat(4, 3)) == "AUTO.LOITER"  # … and Hold is theirs now


def _sent(fake: FakePX4, kind: str) -> list[Any]:
    return [m for m in fake.sent if m.get_type() == kind]


def test_commands_go_on_the_wire_as_px4_takes_them() -> None:
    px4, fake = PX4(), FakePX4({})
    link = link_to(fake)
    px4.send(link, SetMode(1, "GUIDED"), HOME)
    px4.send(link, Arm(2), HOME)
    px4.send(link, Takeoff(3, 45.0), HOME)
    longs = _sent(fake, "COMMAND_LONG")
    assert (longs[0].command, longs[0].param2, longs[0].param3) == (M.MAV_CMD_DO_SET_MODE, 4, 3)
    assert (longs[1].command, longs[1].param1) == (M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    # NAV_TAKEOFF's altitude is above sea level, by the vehicle's own home (500.7 m).
    assert longs[2].command == M.MAV_CMD_NAV_TAKEOFF
    assert longs[2].param7 == pytest.approx(500.7 + 45.0, abs=1e-3)

    sent = px4.send(link, GoTo(4, (30.0, -20.0, 12.0), 90.0), HOME)
    (go,) = _sent(fake, "COMMAND_INT")
    assert sent.mav_cmd == go.command == M.MAV_CMD_DO_REPOSITION
    assert go.frame == M.MAV_FRAME_GLOBAL_INT  # the only frame PX4 takes it in
    assert go.param4 == pytest.approx(math.pi / 2)  # PX4 reads the yaw in radians
    east, north, _ = enu_from_geo(HOME, GeoPoint(go.x / 1e7, go.y / 1e7, HOME.alt_amsl_m))
    assert (east, north) == pytest.approx((30.0, -20.0), abs=0.02)
    assert go.z == pytest.approx(500.7 + 12.0, abs=1e-3)
    px4.send(link, GoTo(5, (0.0, 0.0, 12.0), None), HOME)
    assert math.isnan(_sent(fake, "COMMAND_INT")[-1].param4)  # no heading: PX4 chooses


def test_the_gimbal_is_taken_once_then_pointed_with_the_manager() -> None:
    px4, fake = PX4(), FakePX4({})
    link = link_to(fake)
    px4.send(link, SetGimbal(1, -90.0), HOME)
    sent = px4.send(link, SetGimbal(2, 0.0, 10.0), HOME)
    commands = [m.command for m in _sent(fake, "COMMAND_LONG")]
    assert commands == [
        M.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE,  # PX4 denies PITCHYAW from a GCS without it
        M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
        M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
    ]
    configure, _, last = _sent(fake, "COMMAND_LONG")
    assert (configure.param1, configure.param2) == (255, M.MAV_COMP_ID_MISSIONPLANNER)
    assert (last.param1, last.param2) == (0.0, 10.0)
    assert sent.mav_cmd == M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW


def test_hints_name_px4s_parameters() -> None:
    px4 = PX4()
    never_set = px4.gimbal_fix(lambda name: -1.0 if name == "MNT_MODE_IN" else None)
    assert "MNT_MODE_IN=4" in never_set and "MNT_MODE_OUT" in never_set and "MNT1_" not in never_set
    assert "MNT_MIN_PITCH=-90" in px4.pitch_fix() and "MNT_MAX_PITCH=0" in px4.pitch_fix()


@pytest.mark.parametrize(
    ("params", "alt", "radius"),
    [
        ({"GF_ACTION": 2, "GF_MAX_VER_DIST": 50, "GF_MAX_HOR_DIST": 0}, 50, None),
        ({"GF_ACTION": 3, "GF_MAX_VER_DIST": 0, "GF_MAX_HOR_DIST": 80}, None, 80),
        ({"GF_ACTION": 1, "GF_MAX_VER_DIST": 50, "GF_MAX_HOR_DIST": 80}, None, None),  # warns
        ({"GF_ACTION": 0, "GF_MAX_VER_DIST": 50, "GF_MAX_HOR_DIST": 80}, None, None),  # off
    ],
)
def test_the_fence_is_px4s_geofence(
    params: dict[str, float], alt: float | None, radius: float | None
) -> None:
    fence = PX4().fence(params.get)
    if alt is None and radius is None:
        assert fence is None or (fence.alt_max_m, fence.radius_m) == (None, None)
        return
    assert fence is not None
    assert (fence.alt_max_m, fence.radius_m) == (alt, radius)
    assert (fence.alt_param, fence.radius_param) == ("GF_MAX_VER_DIST", "GF_MAX_HOR_DIST")


_ENVELOPE = Envelope(altitude_m=65.3, distance_m=57.0)


def test_preflight_stops_at_px4s_geofence_with_its_parameter_named() -> None:
    fake = FakePX4({}, params={"GF_ACTION": 2, "GF_MAX_VER_DIST": 50, "GF_MAX_HOR_DIST": 0})
    with pytest.raises(PreflightError, match=r"GF_MAX_VER_DIST=50 m .* set GF_MAX_VER_DIST=71"):
        check_fence(link_to(fake), PX4(), _ENVELOPE)
    fake = FakePX4({}, params={"GF_ACTION": 2, "GF_MAX_VER_DIST": 0, "GF_MAX_HOR_DIST": 40})
    with pytest.raises(PreflightError, match=r"GF_MAX_HOR_DIST=40 m from home"):
        check_fence(link_to(fake), PX4(), _ENVELOPE)
    fake = FakePX4({}, params={"GF_ACTION": 2, "GF_MAX_VER_DIST": 120, "GF_MAX_HOR_DIST": 200})
    check_fence(link_to(fake), PX4(), _ENVELOPE)  # room enough: passes


def test_offboard_streams_setpoints_then_asks_for_offboard() -> None:
    """MAVSDK's way: setpoints first (PX4 refuses OFFBOARD without them), at least 2 Hz, and
    OFFBOARD asked for again until shown; a mode change stops the stream."""
    now = [0.0]
    px4, fake = PX4(movement="offboard"), FakePX4({})
    link = link_to(fake, clock=lambda: now[0])
    sent = px4.send(link, GoTo(1, (10.0, 0.0, 20.0), None), HOME)
    assert sent.mav_cmd == 0  # no ACK for setpoints
    for tenth in range(1, 31):  # three seconds, the runner's loop every 0.1 s
        now[0] = tenth * 0.1
        px4.tick(link, now[0], HOME)
    setpoints = _sent(fake, "SET_POSITION_TARGET_GLOBAL_INT")
    assert 2 * 3 <= len(setpoints) <= 14  # every 0.25 s: above PX4's 2 Hz, not every turn
    assert setpoints[-1].coordinate_frame == M.MAV_FRAME_GLOBAL_INT
    assert setpoints[-1].alt == pytest.approx(500.7 + 20.0, abs=1e-3)
    asks = [m for m in _sent(fake, "COMMAND_LONG") if m.command == M.MAV_CMD_DO_SET_MODE]
    assert len(asks) == 3  # after 0.5 s of setpoints, then each second it is not shown
    assert (asks[0].param2, asks[0].param3) == (6, 0)  # OFFBOARD
    px4.send(link, SetMode(2, "RTL"), HOME)
    before = len(_sent(fake, "SET_POSITION_TARGET_GLOBAL_INT"))
    now[0] = 10.0
    px4.tick(link, now[0], HOME)
    assert len(_sent(fake, "SET_POSITION_TARGET_GLOBAL_INT")) == before


def test_a_gimbal_v1_mount_is_pointed_with_do_mount_control() -> None:
    """PX4 with MNT_MODE_IN=3 takes DO_MOUNT_CONTROL and has no gimbal manager (it denies
    GIMBAL_MANAGER_INFORMATION): the pitch range comes from its parameters."""
    params: dict[str, float] = {"MNT_MODE_IN": 3, "MNT_MIN_PITCH": -90, "MNT_MAX_PITCH": 0}
    px4, fake = PX4(), FakePX4({}, params=params)
    link = link_to(fake)
    assert check_gimbal(link, px4) == (-90.0, 0.0)
    sent = px4.send(link, SetGimbal(1, -45.0), HOME)
    assert sent.mav_cmd == _sent(fake, "COMMAND_LONG")[-1].command == M.MAV_CMD_DO_MOUNT_CONTROL
    fake = FakePX4({}, params={**params, "MNT_MAX_PITCH": -20})
    with pytest.raises(PreflightError, match="MNT_MIN_PITCH=-90 and MNT_MAX_PITCH=0"):
        check_gimbal(link_to(fake), PX4())
    fake = FakePX4({}, params={**params, "MNT_MODE_IN": -1})
    with pytest.raises(PreflightError, match="no gimbal: set MNT_MODE_IN=4"):
        check_gimbal(link_to(fake), PX4())


def test_integer_parameters_are_read_and_set_bytewise_as_px4_encodes_them() -> None:
    """PX4 puts an INT32 parameter's bytes where the float goes: GF_ACTION=2 is 2.8e-45 read
    as a float, and MNT_MODE_IN=-1 is a NaN."""
    fake = FakePX4({}, params={"GF_ACTION": 2, "MPC_XY_CRUISE": 5.0, "MNT_MODE_IN": -1})
    link = link_to(fake)
    reader = param_reader(link, PX4(), None)
    assert (reader("GF_ACTION"), reader("MNT_MODE_IN"), reader("MPC_XY_CRUISE")) == (2, -1, 5)
    set_vehicle_params(link, (("GF_ACTION", 3.0), ("MPC_XY_CRUISE", 8.0)), PX4())
    assert fake.params == {"GF_ACTION": 3, "MPC_XY_CRUISE": 8.0, "MNT_MODE_IN": -1}
    with pytest.raises(ParamError, match="no such parameter"):
        set_vehicle_params(link, (("NOPE", 1.0),), PX4())
