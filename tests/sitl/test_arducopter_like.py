"""The built-in vehicle answers as ArduCopter does where issue 18 found them apart: no mount
by default, a mount type read at boot, arming refused while it boots, a stabilised mount's
residual roll, and the nose turned toward the target (WP_YAW_BEHAVIOR)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from uavtool.link import VehicleLink
from uavtool.link.client import gimbal_camera_pose
from uavtool.mavlink import mavlink as M
from uavtool.sitl import SitlConfig
from uavtool.sitl.lockstep import LockstepTransport

MOUNT = (("MNT1_TYPE", 1.0),)


@contextmanager
def vehicle(**config: Any) -> Iterator[tuple[LockstepTransport, VehicleLink]]:
    transport = LockstepTransport(SitlConfig(endpoints=(), start_unix_us=0, **config), speedup=None)
    link = VehicleLink(transport, clock=transport.clock, announce=False)
    try:
        link.wait_vehicle(30.0)
        yield transport, link
    finally:
        transport.close()


def command(link: VehicleLink, cmd: int, *params: float) -> tuple[int, list[str]]:
    """The ACK's result and the STATUSTEXTs that came with it."""
    link.command_long(cmd, *params)
    texts: list[str] = []
    deadline = link.clock() + 3.0
    while link.clock() < deadline:
        for msg in link.poll(0.05):
            if msg.get_type() == "STATUSTEXT":
                texts.append(msg.text)
            if msg.get_type() == "COMMAND_ACK" and msg.command == cmd:
                return int(msg.result), texts
    raise AssertionError(f"no ACK for command {cmd}")


def heard(link: VehicleLink, kind: str, seconds: float) -> list[Any]:
    out: list[Any] = []
    deadline = link.clock() + seconds
    while link.clock() < deadline:
        out += [m for m in link.poll(0.05) if m.get_type() == kind]
    return out


def test_no_mount_by_default_mount_control_fails_silently() -> None:
    with vehicle() as (_, link):
        result, texts = command(link, M.MAV_CMD_DO_MOUNT_CONTROL, -90, 0, 0, 0, 0, 0, 2)
        assert result == M.MAV_RESULT_FAILED
        assert texts == []  # ArduCopter sends no STATUSTEXT either
        result, _ = command(
            link, M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_GIMBAL_MANAGER_INFORMATION
        )
        assert result == M.MAV_RESULT_ACCEPTED  # a known message, nothing to send
        assert heard(link, "GIMBAL_MANAGER_INFORMATION", 1.0) == []
        assert heard(link, "GIMBAL_DEVICE_ATTITUDE_STATUS", 1.0) == []


def test_a_mount_set_at_run_time_needs_a_reboot() -> None:
    with vehicle() as (_, link):
        link.send(M.MAVLink_param_set_message(1, 1, b"MNT1_TYPE", 1.0, M.MAV_PARAM_TYPE_INT8))
        heard(link, "PARAM_VALUE", 0.5)
        command(link, M.MAV_CMD_DO_SET_MODE, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4)
        result, texts = command(link, M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        assert result == M.MAV_RESULT_FAILED
        assert "Arm: Mount: check TYPE" in texts
        result, _ = command(link, M.MAV_CMD_DO_MOUNT_CONTROL, -90, 0, 0, 0, 0, 0, 2)
        assert result == M.MAV_RESULT_FAILED


def test_a_mount_at_boot_answers_and_reports_its_roll() -> None:
    with vehicle(params=MOUNT, mount_roll_trim_deg=0.13) as (_, link):
        result, _ = command(link, M.MAV_CMD_DO_MOUNT_CONTROL, -90, 0, 0, 0, 0, 0, 2)
        assert result == M.MAV_RESULT_ACCEPTED
        heard(link, "ATTITUDE", 2.0)  # the gimbal turns at 90°/s
        status = heard(link, "GIMBAL_DEVICE_ATTITUDE_STATUS", 0.5)[-1]
        assert status.flags & M.GIMBAL_DEVICE_FLAGS_YAW_IN_VEHICLE_FRAME
        assert abs(status.q[1]) > 1e-4  # not a pure pitch: the stabilising roll
        pose = gimbal_camera_pose(status, pos_enu_m=(0.0, 0.0, 0.0), vehicle_heading_deg=353.0)
        assert pose is not None
        assert pose.pitch_deg < -89.0
        assert abs((pose.heading_deg + pose.roll_deg - 353.0 + 180) % 360 - 180) < 0.5


def test_arming_is_refused_while_it_boots() -> None:
    with vehicle(params=MOUNT, arming_settle_s=4.0) as (transport, link):
        command(link, M.MAV_CMD_DO_SET_MODE, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4)
        seen: list[str] = []
        while transport.clock() < 10.0:
            result, texts = command(link, M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
            if result == M.MAV_RESULT_ACCEPTED:
                break
            seen += texts
            heard(link, "HEARTBEAT", 0.5)
        assert result == M.MAV_RESULT_ACCEPTED
        assert transport.clock() >= 4.0
        assert "Arm: Gyros inconsistent" in seen
        assert "Arm: Need Position Estimate" in seen


def fly_east(behaviour: float) -> float:
    with vehicle(params=(*MOUNT, ("WP_YAW_BEHAVIOR", behaviour)), home_heading_deg=0.0) as (
        _,
        link,
    ):
        command(link, M.MAV_CMD_DO_SET_MODE, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4)
        command(link, M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        command(link, M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, 10)
        heard(link, "HEARTBEAT", 12.0)
        link.send(
            M.MAVLink_set_position_target_local_ned_message(
                0, 1, 1, M.MAV_FRAME_LOCAL_NED, 0b0000_1111_1111_1000, 0, 30, -10,
                0, 0, 0, 0, 0, 0, 0, 0,
            )
        )  # fmt: skip
        heard(link, "HEARTBEAT", 4.0)
        return float(link.state.position.hdg) / 100.0


def test_the_nose_follows_the_travel_unless_told_not_to() -> None:
    assert abs(fly_east(2) - 90.0) < 3.0  # ArduCopter's default: face the target
    assert abs((fly_east(0) + 180) % 360 - 180) < 3.0  # 0: hold the heading
