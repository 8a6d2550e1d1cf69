"""MAVSDK-Python (the C++ library in the wheel) accepts the vehicle as a real ArduPilot."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tests.sitl.conftest import MOUNT
from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl, SitlConfig

mavsdk = pytest.importorskip("mavsdk")
from mavsdk.plugins.action import Action  # noqa: E402
from mavsdk.plugins.gimbal import ControlMode, Gimbal, GimbalMode, SendMode  # noqa: E402
from mavsdk.plugins.mission_raw import MissionItem, MissionRaw  # noqa: E402
from mavsdk.plugins.offboard import Offboard, PositionNedYaw  # noqa: E402
from mavsdk.plugins.param import Param  # noqa: E402
from mavsdk.plugins.telemetry import Telemetry  # noqa: E402


def _until(check: Callable[[], Any], what: str, timeout: float = 20.0) -> Any:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = check()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def drone() -> Iterator[tuple[Sitl, Any]]:
    config = SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=10, params=MOUNT)
    with Sitl(config) as sitl:
        sdk = mavsdk.Mavsdk(
            mavsdk.Configuration.create_with_component_type(mavsdk.ComponentType.GROUND_STATION)
        )
        assert (
            sdk.add_any_connection(f"tcpout://127.0.0.1:{sitl.ports[0]}")
            == mavsdk.ConnectionResult.SUCCESS
        )
        system = sdk.first_autopilot(10.0)
        assert system is not None, "MAVSDK did not discover an autopilot"
        try:
            yield sitl, system
        finally:
            sdk.destroy()


def test_discovery_health_params_and_flight(drone: tuple[Sitl, Any]) -> None:
    sitl, system = drone
    telemetry, action, param = Telemetry(system), Action(system), Param(system)
    health = _until(
        lambda: (
            (h := telemetry.health()).is_global_position_ok
            and h.is_home_position_ok
            and h.is_armable
            and h
        ),
        "healthy",
    )
    assert health.is_gyrometer_calibration_ok and health.is_local_position_ok
    assert param.get_param_int("RTL_ALT") == 1500
    param.set_param_int("RTL_ALT", 2500)
    assert param.get_param_int("RTL_ALT") == 2500
    param.set_param_float("WPNAV_SPEED", 600.0)
    assert param.get_param_float("WPNAV_SPEED") == pytest.approx(600.0)

    action.set_takeoff_altitude(10.0)
    action.arm()
    action.takeoff()
    _until(lambda: telemetry.position().relative_altitude_m > 9.7, "10 m")

    home = sitl.config.home
    target = geo_from_enu(home, 15.0, 20.0, 12.0)
    action.goto_location(target.lat_deg, target.lon_deg, target.alt_amsl_m, math.nan)
    _until(
        lambda: (
            abs(telemetry.position().latitude_deg - target.lat_deg) < 2e-6
            and abs(telemetry.position().longitude_deg - target.lon_deg) < 2e-6
        ),
        "goto",
    )
    assert telemetry.position().relative_altitude_m == pytest.approx(12.0, abs=0.1)

    # Yaw the way MAVSDK does it on ArduPilot: an offboard (GUIDED) position target with yaw.
    offboard = Offboard(system)
    offboard.set_position_ned(PositionNedYaw(20.0, 15.0, -12.0, 90.0))
    offboard.start()
    _until(lambda: abs(telemetry.heading().heading_deg - 90.0) < 1.0, "yaw 90")
    offboard.stop()

    action.land()
    _until(lambda: not telemetry.armed(), "landed and disarmed", timeout=30)
    assert telemetry.position().relative_altitude_m < 0.1


def test_mission_round_trip_via_mission_raw(drone: tuple[Sitl, Any]) -> None:
    sitl, system = drone
    home: GeoPoint = sitl.config.home
    rel = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    # With ArduPilot, item 0 is home: a MissionRaw user sends a placeholder there.
    items = [
        MissionItem(
            0,
            M.MAV_FRAME_GLOBAL_INT,
            M.MAV_CMD_NAV_WAYPOINT,
            0,
            1,
            0,
            0,
            0,
            0,
            home.lat_e7,
            home.lon_e7,
            home.alt_amsl_m,
            0,
        ),
        MissionItem(1, rel, M.MAV_CMD_NAV_TAKEOFF, 1, 1, 0, 0, 0, 0, 0, 0, 10.0, 0),
        MissionItem(
            2,
            rel,
            M.MAV_CMD_NAV_WAYPOINT,
            0,
            1,
            0,
            0,
            0,
            0,
            home.lat_e7 + 1000,
            home.lon_e7,
            15.0,
            0,
        ),
        MissionItem(
            3,
            rel,
            M.MAV_CMD_NAV_WAYPOINT,
            0,
            1,
            2,
            0,
            0,
            0,
            home.lat_e7,
            home.lon_e7 + 1000,
            15.0,
            0,
        ),
        MissionItem(4, rel, M.MAV_CMD_NAV_LAND, 0, 1, 0, 0, 0, 0, 0, 0, 0.0, 0),
    ]
    mission = MissionRaw(system)
    mission.upload_mission(items)
    got = mission.download_mission()
    key = [(i.seq, i.frame, i.command, i.param1, i.x, i.y, i.z) for i in got]
    assert key == [(i.seq, i.frame, i.command, i.param1, i.x, i.y, i.z) for i in items]


def test_gimbal_angles_reflected(drone: tuple[Sitl, Any]) -> None:
    _sitl, system = drone
    gimbal = Gimbal(system)
    gimbals = _until(lambda: gimbal.gimbal_list().gimbals, "gimbal discovered")
    gimbal_id = gimbals[0].gimbal_id
    gimbal.take_control(gimbal_id, ControlMode.PRIMARY)
    gimbal.set_angles(gimbal_id, 0.0, -45.0, 30.0, GimbalMode.YAW_FOLLOW, SendMode.ONCE)

    def angles() -> tuple[float, float]:
        euler = gimbal.get_attitude(gimbal_id).euler_angle_forward
        return euler.pitch_deg, euler.yaw_deg

    _until(lambda: abs(angles()[0] + 45.0) < 1.0 and abs(angles()[1] - 30.0) < 1.0, "gimbal -45/30")
