"""Identity: HEARTBEAT, AUTOPILOT_VERSION, system status, sysid/instance."""

from __future__ import annotations

from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl, SitlConfig


def test_heartbeat_identifies_an_arducopter(client: Client) -> None:
    hb = client.wait_for("HEARTBEAT")
    assert hb.get_srcSystem() == 1 and hb.get_srcComponent() == 1
    assert hb.type == M.MAV_TYPE_QUADROTOR
    assert hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert hb.base_mode & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    assert not hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
    assert hb.custom_mode == 0  # STABILIZE at boot, as ArduCopter
    assert hb.system_status == M.MAV_STATE_STANDBY
    assert hb.mavlink_version == 3
    assert client.frames[-1].raw[0] == 0xFD  # MAVLink 2 framing


def test_heartbeat_is_1hz_in_sim_time(client: Client) -> None:
    client.wait_for("SYSTEM_TIME")
    start = client.latest["SYSTEM_TIME"].time_boot_ms
    n0 = sum(1 for m in client.received if m.get_type() == "HEARTBEAT")
    client.wait_until(
        lambda c: c.latest["SYSTEM_TIME"].time_boot_ms >= start + 10_000, what="10 s of sim time"
    )
    n = sum(1 for m in client.received if m.get_type() == "HEARTBEAT") - n0
    # SYSTEM_TIME comes once a second too, so each end of the window may be up to a second
    # late: 10 s of a 1 Hz heartbeat is 8 to 12 of them (2 Hz would be 20, 0.5 Hz 5).
    assert 8 <= n <= 12


def test_armed_heartbeat_is_active_with_safety_armed(client: Client) -> None:
    client.takeoff(5)
    hb = client.wait_for("HEARTBEAT")
    assert hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
    assert hb.custom_mode == 4
    assert hb.system_status == M.MAV_STATE_ACTIVE


def test_autopilot_version_capabilities_and_stable_uid(client: Client, vehicle: Sitl) -> None:
    ack = client.command(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    assert ack.result == M.MAV_RESULT_ACCEPTED
    version = client.wait_for("AUTOPILOT_VERSION")
    for cap in (
        M.MAV_PROTOCOL_CAPABILITY_MISSION_INT,
        M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT,
        M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT,
        M.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_LOCAL_NED,
        M.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT,
        M.MAV_PROTOCOL_CAPABILITY_MAVLINK2,
    ):
        assert version.capabilities & cap
    assert not version.capabilities & M.MAV_PROTOCOL_CAPABILITY_FTP  # we only NAK FTP
    assert version.uid != 0
    with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20)) as other:
        c2 = Client.tcp(other.ports[0])
        c2.command(M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, 1)
        assert c2.wait_for("AUTOPILOT_VERSION").uid == version.uid
        c2.close()


def test_instance_offsets_sysid_and_ports() -> None:
    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0", "udpin:127.0.0.1:0"), instance=2, speedup=20
    )
    with Sitl(config) as sitl:
        c = Client.tcp(sitl.ports[0])
        hb = c.wait_for("HEARTBEAT")
        assert hb.get_srcSystem() == 3
        c.close()
    from uavtool.sitl.links import parse_endpoint

    assert parse_endpoint("tcpin:127.0.0.1:5760").offset(2).port == 5780
