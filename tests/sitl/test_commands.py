"""COMMAND_LONG / COMMAND_INT: exactly one ACK each, results and reasons."""

from __future__ import annotations

import math

import pytest

from tests.sitl.client import Client
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl

ACCEPTED = M.MAV_RESULT_ACCEPTED


def _acks(client: Client, command: int) -> int:
    client.pump(0.3)
    return sum(1 for m in client.received if m.get_type() == "COMMAND_ACK" and m.command == command)


@pytest.mark.parametrize(
    "command",
    [
        M.MAV_CMD_COMPONENT_ARM_DISARM,
        M.MAV_CMD_NAV_TAKEOFF,
        31999,
        M.MAV_CMD_DO_SET_MODE,
        M.MAV_CMD_REQUEST_MESSAGE,
    ],
)
def test_exactly_one_ack_per_command(client: Client, command: int) -> None:
    client.send(M.MAVLink_command_long_message(1, 1, command, 0, 0, 0, 0, 0, 0, 0, 0))
    assert _acks(client, command) == 1
    client.send(M.MAVLink_command_int_message(1, 1, 0, command, 0, 0, 0, 0, 0, 0, 0, 0, 0))
    assert _acks(client, command) == 2


def test_unknown_command_is_unsupported(client: Client) -> None:
    assert client.command(31999).result == M.MAV_RESULT_UNSUPPORTED


def test_commands_for_another_system_are_ignored(client: Client) -> None:
    client.send(
        M.MAVLink_command_long_message(
            42, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0
        )
    )
    client.send(
        M.MAVLink_command_long_message(
            1, 99, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0
        )
    )
    assert _acks(client, M.MAV_CMD_COMPONENT_ARM_DISARM) == 0


def test_takeoff_refused_unless_guided_and_armed_with_reason(client: Client) -> None:
    ack = client.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 10)
    assert ack.result == M.MAV_RESULT_FAILED
    assert "GUIDED" in client.reason()
    client.set_mode("GUIDED")
    assert client.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 10).result == M.MAV_RESULT_FAILED
    assert "not armed" in client.reason()


def test_arm_refused_in_non_armable_mode_unless_forced(client: Client) -> None:
    assert client.set_mode("RTL").result == ACCEPTED
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_FAILED
    assert "not armable" in client.reason()
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1, 21196).result == ACCEPTED


def test_disarm_in_flight_needs_force(client: Client) -> None:
    client.takeoff(5)
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 0).result == M.MAV_RESULT_DENIED
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 21196).result == ACCEPTED
    client.wait_until(lambda c: c.alt_m() < 0.05, what="fall to the ground")


def test_set_mode_command_and_message(client: Client) -> None:
    for name, number in (("LOITER", 5), ("BRAKE", 17), ("GUIDED", 4), ("STABILIZE", 0)):
        assert client.set_mode(name).result == ACCEPTED
        client.wait_for("HEARTBEAT", lambda m, n=number: m.custom_mode == n)
    assert client.command(M.MAV_CMD_DO_SET_MODE, 1, 99).result == M.MAV_RESULT_DENIED
    client.send(M.MAVLink_set_mode_message(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4))
    assert (
        client.wait_for("COMMAND_ACK", lambda m: m.command == M.MAVLINK_MSG_ID_SET_MODE).result
        == ACCEPTED
    )
    # AUTO without a mission is refused with a reason.
    assert client.set_mode("AUTO").result == M.MAV_RESULT_FAILED


def test_land_and_rtl(client: Client) -> None:
    client.takeoff(8)
    assert client.command(M.MAV_CMD_NAV_LAND).result == ACCEPTED
    client.wait_for("HEARTBEAT", lambda m: m.custom_mode == 9)
    client.wait_until(
        lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
        what="disarm after landing",
    )
    assert client.alt_m() < 0.05
    client.takeoff(6)
    assert client.command(M.MAV_CMD_NAV_RETURN_TO_LAUNCH).result == ACCEPTED
    client.wait_for("HEARTBEAT", lambda m: m.custom_mode == 6)


def test_condition_yaw_absolute_and_relative(client: Client) -> None:
    client.takeoff(5)
    assert client.command(M.MAV_CMD_CONDITION_YAW, 90, 30, 1, 0).result == ACCEPTED
    client.wait_until(lambda c: abs(c.latest["VFR_HUD"].heading - 90) <= 1, what="yaw 90")
    assert client.command(M.MAV_CMD_CONDITION_YAW, 45, 0, -1, 1).result == ACCEPTED
    client.wait_until(lambda c: abs(c.latest["VFR_HUD"].heading - 45) <= 1, what="yaw 45")


def test_change_speed_limits_ground_speed(client: Client, vehicle: Sitl) -> None:
    client.takeoff(5)
    assert client.command(M.MAV_CMD_DO_CHANGE_SPEED, 1, 3.0, -1).result == ACCEPTED
    client.send(
        M.MAVLink_set_position_target_local_ned_message(
            0, 1, 1, M.MAV_FRAME_LOCAL_NED, 0b110111111000, 80, 0, -5, 0, 0, 0, 0, 0, 0, 0, 0
        )
    )
    client.pump(3.0)
    speeds = [m.groundspeed for m in client.received if m.get_type() == "VFR_HUD"]
    assert max(speeds) == pytest.approx(3.0, rel=0.04)  # a few % over, catching up its target


def test_speeds_asked_for_stay_within_the_speed_parameters_ranges(client: Client) -> None:
    """DO_CHANGE_SPEED 1e38 and a 1e6 m/s velocity stream are bounded to WPNAV_SPEED's top
    (20 m/s), as ArduCopter bounds them (a 2 km move reached 70.6 m/s, a velocity stream
    503 m/s). The airframe itself is slower still: at ANGLE_MAX (30°) its drag balances its
    thrust near 10 m/s in still air."""
    client.takeoff(5)
    assert client.command(M.MAV_CMD_DO_CHANGE_SPEED, 1, 1e38, -1).result == ACCEPTED
    position_only, velocity_only = 0b110111111000, 0b110111000111
    client.send(
        M.MAVLink_set_position_target_local_ned_message(
            0, 1, 1, M.MAV_FRAME_LOCAL_NED, position_only, 2000, 0, -5, 0, 0, 0, 0, 0, 0, 0, 0
        )
    )
    client.pump(3.0)  # 60 s of vehicle time: long past reaching its top speed
    for _ in range(15):  # a stream, as an attacker would send it, 3 s of vehicle time apart
        client.send(
            M.MAVLink_set_position_target_local_ned_message(
                0, 1, 1, M.MAV_FRAME_LOCAL_NED, velocity_only, 0, 0, 0, 1e6, 0, 0, 0, 0, 0, 0, 0
            )
        )
        client.pump(0.15)
    speeds = [m.groundspeed for m in client.received if m.get_type() == "VFR_HUD"]
    assert 9.5 < max(speeds) < 11.0  # as fast as a 30° lean goes, within 20 m/s


@pytest.mark.parametrize("frame", [M.MAV_FRAME_GLOBAL_INT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT])
def test_reposition_honours_altitude_frame(client: Client, vehicle: Sitl, frame: int) -> None:
    client.takeoff(5)
    home = vehicle.config.home
    target = GeoPoint(home.lat_deg + 0.0002, home.lon_deg + 0.0001, 0)
    alt = 12.0 if frame == M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT else home.alt_amsl_m + 12.0
    ack = client.command_int(
        M.MAV_CMD_DO_REPOSITION, frame, target.lat_e7, target.lon_e7, alt, -1, 0, 0, math.nan
    )
    assert ack.result == ACCEPTED
    client.wait_until(lambda c: abs(c.alt_m() - 12.0) < 0.1, what="12 m")
    e_t, n_t, _ = enu_from_geo(home, target)

    def dist_m(c: Client) -> float:
        pos = c.latest["GLOBAL_POSITION_INT"]
        e, n, _ = enu_from_geo(home, GeoPoint(pos.lat / 1e7, pos.lon / 1e7, 0))
        return math.hypot(e - e_t, n - n_t)

    client.wait_until(lambda c: dist_m(c) < 0.3, what="reach target")


def test_get_home_position_and_request_message(client: Client, vehicle: Sitl) -> None:
    assert client.command(M.MAV_CMD_GET_HOME_POSITION).result == ACCEPTED
    home = client.wait_for("HOME_POSITION")
    assert home.latitude == vehicle.config.home.lat_e7
    assert home.altitude == round(vehicle.config.home.alt_amsl_m * 1000)
    assert (
        client.command(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE).result
        == ACCEPTED
    )
    assert client.command(M.MAV_CMD_REQUEST_MESSAGE, 9999).result == M.MAV_RESULT_FAILED


def test_gimbal_v1_and_v2(client: Client) -> None:
    def pitch_deg(c: Client) -> float:
        w, x, y, z = c.latest["GIMBAL_DEVICE_ATTITUDE_STATUS"].q
        return math.degrees(math.asin(2 * (w * y - z * x)))

    def yaw_deg(c: Client) -> float:
        w, x, y, z = c.latest["GIMBAL_DEVICE_ATTITUDE_STATUS"].q
        return math.degrees(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))

    assert (
        client.command(
            M.MAV_CMD_DO_MOUNT_CONTROL, -90, 0, 0, 0, 0, 0, M.MAV_MOUNT_MODE_MAVLINK_TARGETING
        ).result
        == ACCEPTED
    )
    client.wait_until(lambda c: abs(pitch_deg(c) + 90) < 0.5, what="nadir")
    assert (
        client.command(
            M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW, -30, 20, math.nan, math.nan, 0, 0, 0
        ).result
        == ACCEPTED
    )
    client.wait_until(
        lambda c: abs(pitch_deg(c) + 30) < 0.5 and abs(yaw_deg(c) - 20) < 0.5, what="-30/20"
    )
    q = [math.cos(math.radians(-10) / 2), 0.0, math.sin(math.radians(-10) / 2), 0.0]
    client.send(
        M.MAVLink_gimbal_manager_set_attitude_message(1, 1, 0, 0, q, math.nan, math.nan, math.nan)
    )
    client.wait_until(lambda c: abs(pitch_deg(c) + 10) < 0.5, what="-10 via SET_ATTITUDE")
    client.wait_for("GIMBAL_MANAGER_STATUS")
    assert (
        client.command(
            M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_GIMBAL_MANAGER_INFORMATION
        ).result
        == ACCEPTED
    )
    info = client.wait_for("GIMBAL_MANAGER_INFORMATION")
    assert info.pitch_min == pytest.approx(math.radians(-90))
    assert (
        client.command(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_GIMBAL_DEVICE_INFORMATION).result
        == ACCEPTED
    )
    assert client.wait_for("GIMBAL_DEVICE_INFORMATION").gimbal_device_id == 1
    # Pitch is clamped to the mount's range.
    client.command(M.MAV_CMD_DO_MOUNT_CONTROL, 45, 0, 0)
    client.wait_until(lambda c: abs(pitch_deg(c)) < 0.5, what="clamped to 0")


def test_message_interval_and_legacy_data_stream(client: Client) -> None:
    assert (
        client.command(M.MAV_CMD_SET_MESSAGE_INTERVAL, M.MAVLINK_MSG_ID_ATTITUDE, 20_000).result
        == ACCEPTED
    )
    client.command(M.MAV_CMD_GET_MESSAGE_INTERVAL, M.MAVLINK_MSG_ID_ATTITUDE)
    assert client.wait_for("MESSAGE_INTERVAL").interval_us == 20_000
    client.wait_for("SYSTEM_TIME")
    t0 = client.latest["SYSTEM_TIME"].time_boot_ms
    n0 = sum(1 for m in client.received if m.get_type() == "ATTITUDE")
    client.wait_until(lambda c: c.latest["SYSTEM_TIME"].time_boot_ms >= t0 + 5000, what="5 s")
    n = sum(1 for m in client.received if m.get_type() == "ATTITUDE") - n0
    assert 225 <= n <= 275  # 50 Hz for 5 s (± the window's edges, which telemetry order blurs)
    assert (
        client.command(M.MAV_CMD_SET_MESSAGE_INTERVAL, M.MAVLINK_MSG_ID_ATTITUDE, -1).result
        == ACCEPTED
    )
    client.pump(0.3)
    n1 = sum(1 for m in client.received if m.get_type() == "ATTITUDE")
    client.pump(0.5)
    assert sum(1 for m in client.received if m.get_type() == "ATTITUDE") == n1
    client.send(M.MAVLink_request_data_stream_message(1, 1, M.MAV_DATA_STREAM_EXTRA1, 4, 1))
    client.wait_for("ATTITUDE", timeout=3)
    client.send(M.MAVLink_request_data_stream_message(1, 1, M.MAV_DATA_STREAM_ALL, 0, 0))
    client.pump(0.3)
    n2 = sum(1 for m in client.received if m.get_type() == "GLOBAL_POSITION_INT")
    client.pump(0.5)
    assert sum(1 for m in client.received if m.get_type() == "GLOBAL_POSITION_INT") == n2
