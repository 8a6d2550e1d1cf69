"""Failsafes with ArduPilot semantics: GCS heartbeat loss, low battery."""

from __future__ import annotations

import time

import pytest

from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl, SitlConfig


def _set(client: Client, name: str, value: float, mav_type: int = M.MAV_PARAM_TYPE_INT8) -> None:
    client.send(M.MAVLink_param_set_message(1, 1, name.encode(), value, mav_type))
    client.wait_for("PARAM_VALUE", lambda m: m.param_id == name)


def _heartbeat_on_each_vehicle_heartbeat(client: Client, seconds: float) -> None:
    """Behave like a GCS paced by the vehicle: one heartbeat per vehicle heartbeat (1 Hz sim)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if any(m.get_type() == "HEARTBEAT" for m in client.pump(0.01)):
            client.heartbeat()


@pytest.fixture
def fast_attitude(client: Client) -> Client:
    client.command(
        M.MAV_CMD_SET_MESSAGE_INTERVAL, M.MAVLINK_MSG_ID_ATTITUDE, 20_000
    )  # 50 Hz: 20 ms resolution
    return client


@pytest.mark.parametrize(("action", "mode"), [(1, 6), (5, 9)])
def test_gcs_failsafe_fires_after_timeout(fast_attitude: Client, action: int, mode: int) -> None:
    client = fast_attitude
    client.takeoff(10)  # no GCS heartbeat seen yet: the failsafe cannot arm itself
    _set(client, "FS_GCS_ENABLE", action)
    _heartbeat_on_each_vehicle_heartbeat(client, 0.5)
    last_hb_ms = client.latest["ATTITUDE"].time_boot_ms
    client.heartbeat()  # the last one: it arrives within a step or two of last_hb_ms
    fired_ms = 0
    while fired_ms <= last_hb_ms:
        # a loaded machine may pace the GCS heartbeats late enough for a failsafe to fire
        # (and clear) before the last one: that one is still queued, and is not under test
        text = client.wait_for("STATUSTEXT", lambda m: m.text == "GCS Failsafe", timeout=10)
        assert text is not None
        fired_ms = client.wait_for("ATTITUDE").time_boot_ms  # the first sample after it
    assert abs((fired_ms - last_hb_ms) / 1000.0 - 5.0) <= 0.5
    hb = client.wait_for("HEARTBEAT", lambda m: m.custom_mode == mode, timeout=3)
    assert hb.system_status == M.MAV_STATE_CRITICAL
    client.heartbeat()
    client.wait_for("STATUSTEXT", lambda m: m.text == "GCS Failsafe Cleared", timeout=3)
    assert client.wait_for("HEARTBEAT", lambda m: m.system_status == M.MAV_STATE_ACTIVE, timeout=3)


def test_gcs_failsafe_never_fires_while_disarmed(client: Client) -> None:
    _set(client, "FS_GCS_ENABLE", 1)
    _heartbeat_on_each_vehicle_heartbeat(client, 0.3)
    t0 = client.wait_for("SYSTEM_TIME").time_boot_ms
    client.wait_until(
        lambda c: c.latest["SYSTEM_TIME"].time_boot_ms > t0 + 15_000, what="15 s sim without GCS"
    )
    assert "GCS Failsafe" not in client.statustexts()
    assert client.latest["HEARTBEAT"].system_status == M.MAV_STATE_STANDBY


def test_gcs_failsafe_disabled_by_default(client: Client) -> None:
    client.heartbeat()
    client.takeoff(5)
    t0 = client.latest["GLOBAL_POSITION_INT"].time_boot_ms
    client.wait_until(lambda c: c.boot_s() * 1000 > t0 + 10_000, what="10 s sim")
    assert "GCS Failsafe" not in client.statustexts()


def test_low_battery_triggers_rtl() -> None:
    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0",), speedup=40, params=(("BATT_CAPACITY", 120),)
    )
    with Sitl(config) as sitl:
        c = Client.tcp(sitl.ports[0])
        c.takeoff(10)
        c.wait_for("STATUSTEXT", lambda m: m.text == "Battery 1 is low", timeout=20)
        c.wait_for("HEARTBEAT", lambda m: m.custom_mode == 6, timeout=3)
        c.close()
