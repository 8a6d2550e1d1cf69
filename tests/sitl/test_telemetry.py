"""Telemetry streamed by default and states clients rely on."""

from __future__ import annotations

from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.sitl.telemetry import Streams

STREAMED = (
    "GLOBAL_POSITION_INT",
    "LOCAL_POSITION_NED",
    "ATTITUDE",
    "VFR_HUD",
    "SYS_STATUS",
    "GPS_RAW_INT",
    "BATTERY_STATUS",
    "HOME_POSITION",
    "EXTENDED_SYS_STATE",
    "SYSTEM_TIME",
    "GIMBAL_DEVICE_ATTITUDE_STATUS",
    "GIMBAL_MANAGER_STATUS",
    "MISSION_CURRENT",
)


def test_default_streams(client: Client) -> None:
    client.pump(2.5)  # 50 s of sim time at 20×: long enough for the slowest stream
    assert set(STREAMED) <= set(client.latest)


def test_sys_status_reports_healthy_and_armable(client: Client) -> None:
    s = client.wait_for("SYS_STATUS")
    for bit in (
        M.MAV_SYS_STATUS_SENSOR_GPS,
        M.MAV_SYS_STATUS_PREARM_CHECK,
        M.MAV_SYS_STATUS_AHRS,
        M.MAV_SYS_STATUS_SENSOR_3D_GYRO,
        M.MAV_SYS_STATUS_SENSOR_3D_ACCEL,
        M.MAV_SYS_STATUS_SENSOR_3D_MAG,
    ):
        assert s.onboard_control_sensors_present & bit
        assert s.onboard_control_sensors_enabled & bit
        assert s.onboard_control_sensors_health & bit
    assert 12000 < s.voltage_battery <= 12600  # a full 3S
    gps = client.wait_for("GPS_RAW_INT")
    assert gps.fix_type >= 3 and gps.satellites_visible >= 10


def test_landed_state_and_battery_drain(client: Client) -> None:
    assert client.wait_for("EXTENDED_SYS_STATE").landed_state == M.MAV_LANDED_STATE_ON_GROUND
    client.set_mode("GUIDED")
    client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    client.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 30)
    assert client.wait_for("EXTENDED_SYS_STATE").landed_state == M.MAV_LANDED_STATE_TAKEOFF
    client.wait_until(lambda c: c.alt_m() > 29.9, what="30 m")
    client.wait_for(
        "EXTENDED_SYS_STATE", lambda m: m.landed_state == M.MAV_LANDED_STATE_IN_AIR, timeout=3
    )
    client.command(M.MAV_CMD_NAV_LAND)
    client.wait_for(
        "EXTENDED_SYS_STATE", lambda m: m.landed_state == M.MAV_LANDED_STATE_LANDING, timeout=3
    )
    states = [m.landed_state for m in client.received if m.get_type() == "EXTENDED_SYS_STATE"]
    order = [s for i, s in enumerate(states) if i == 0 or s != states[i - 1]]
    assert order == [
        M.MAV_LANDED_STATE_ON_GROUND,
        M.MAV_LANDED_STATE_TAKEOFF,
        M.MAV_LANDED_STATE_IN_AIR,
        M.MAV_LANDED_STATE_LANDING,
    ]
    used = [m.current_consumed for m in client.received if m.get_type() == "BATTERY_STATUS"]
    assert used[-1] > used[0]


def test_a_stream_started_between_others_is_due_at_once() -> None:
    """`Streams.due` skips the steps before the soonest stream is due; a stream turned on
    (or sped up) in between is still sent at the next step, then at its rate."""
    streams = Streams()
    streams.due(0)  # every default stream, now
    assert streams.due(1_000_000) == []  # none due 1 ms later
    streams.set_interval(M.MAVLINK_MSG_ID_RAW_IMU, 50_000, 2_000_000)  # 20 Hz from 2 ms
    assert streams.due(2_000_000) == [M.MAVLINK_MSG_ID_RAW_IMU]
    assert streams.due(51_000_000) == []
    assert M.MAVLINK_MSG_ID_RAW_IMU in streams.due(52_000_000)
