"""Issue 20, the vehicle: signing that holds across connections, hostile parameters refused,
UDP peers that expire, and faults isolated to the peer that caused them."""

from __future__ import annotations

import logging
import socket
import time

import pytest

from tests.sitl.client import Client
from tests.sitl.pilot import Pilot
from tests.sitl.udp import settle
from uavtool.mavlink import mavlink as M
from uavtool.mavlink import new_encoder
from uavtool.sitl import Sitl, SitlConfig, links
from uavtool.sitl.links import MAX_UDP_PEERS, UdpSocket
from uavtool.sitl.server import MAX_LINK_FAULTS
from uavtool.sitl.signing import SIGNING_EPOCH_UNIX_US, SigningStreams

KEY = bytes(range(32))
ARM = M.MAV_CMD_COMPONENT_ARM_DISARM


def _acks(c: Client, seconds: float = 0.4) -> list[int]:
    c.pump(seconds)
    return [m.result for m in c.received if m.get_type() == "COMMAND_ACK"]


def test_a_captured_signed_arm_replayed_on_new_connections_is_refused() -> None:
    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0", "udpin:127.0.0.1:0"), speedup=20, signing_key=KEY
    )
    with Sitl(config) as sitl:
        gcs = Client.tcp(sitl.ports[0], signing_key=KEY)
        gcs.wait_for("HEARTBEAT")
        arm = M.MAVLink_command_long_message(1, 1, ARM, 0, 1, 0, 0, 0, 0, 0, 0)
        captured = arm.pack(gcs.enc)  # what an eavesdropper records off the air
        gcs.enc.seq += 1
        gcs.send_raw(captured)
        assert gcs.wait_for("COMMAND_ACK").result == M.MAV_RESULT_ACCEPTED
        assert gcs.command(ARM, 0).result == M.MAV_RESULT_ACCEPTED  # disarmed again
        replay_tcp = Client.tcp(sitl.ports[0])
        replay_tcp.send_raw(captured)
        udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        udp.bind(("127.0.0.1", 0))
        replay_udp = Client(udp, udp_addr=("127.0.0.1", sitl.ports[1]))
        replay_udp.send_raw(captured)
        assert _acks(replay_tcp) == []
        assert _acks(replay_udp) == []
        assert not sitl.autopilot.armed
        assert sitl.signing is not None and sitl.signing.refused >= 2
        for c in (gcs, replay_tcp, replay_udp):
            c.close()


def test_a_forged_timestamp_does_not_lock_the_ground_station_out() -> None:
    with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20, signing_key=KEY)) as sitl:
        gcs = Client.tcp(sitl.ports[0], signing_key=KEY)
        gcs.wait_for("HEARTBEAT")
        # The GCS's own stream (sysid, compid, link id), a far-future timestamp, no valid
        # signature: the CRC does not cover the signature block, so the frame parses.
        frame = bytearray(
            M.MAVLink_command_long_message(1, 1, ARM, 0, 1, 0, 0, 0, 0, 0, 0).pack(gcs.enc)
        )
        frame[-12:-6] = (2**48 - 1).to_bytes(6, "little")
        frame[-6:] = bytes(6)
        attacker = Client.tcp(sitl.ports[0])
        attacker.send_raw(bytes(frame))
        gcs.send_raw(bytes(frame))  # on the GCS's own link too
        assert _acks(attacker) == []
        assert gcs.command(ARM, 1).result == M.MAV_RESULT_ACCEPTED
        assert sitl.autopilot.armed
        gcs.close()
        attacker.close()


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("SIM_WIND_TURB", 3.4e38),
        ("SIM_GPS_NOISE", 3.4e38),
        ("SIM_BARO_RND", 3.4e38),
        ("SIM_BATT_VOLTAGE", -3.4e38),
        ("SIM_SPEEDUP", 1e-30),
        ("LAND_SPEED", -32768),
        ("WPNAV_SPEED", 1e38),
        ("SIM_WIND_SPD", 1e30),
        ("RTL_ALT", float("nan")),
    ],
)
def test_hostile_param_values_are_refused_as_ardupilot_does(name: str, value: float) -> None:
    pilot = Pilot()
    before = pilot.set_param(name, pilot.sitl.autopilot.params[name])
    answer = pilot.set_param(name, value)  # the value the vehicle kept, sent back
    assert answer.param_value == before.param_value
    assert name in pilot.statustexts()[-1]
    assert "range" in pilot.statustexts()[-1] or "finite" in pilot.statustexts()[-1]
    pilot.run(2.0)
    pilot.normal_flight()  # and nothing about the vehicle changed
    assert pilot.sitl.faults == 0


def test_land_speed_cannot_be_set_so_that_land_never_lands() -> None:
    pilot = Pilot()
    pilot.set_param("LAND_SPEED", -32768)
    assert pilot.sitl.autopilot.params["LAND_SPEED"] == 50
    pilot.normal_flight(3.0)


def test_2000_ghost_udp_peers_expire_and_a_flight_is_unaffected(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(links, "UDP_PEER_TIMEOUT_NS", 2 * 10**9)  # real time: don't wait 10 s

    def flight(ghosts: int) -> tuple[float, int]:
        config = SitlConfig(endpoints=("tcpin:127.0.0.1:0", "udpin:127.0.0.1:0"), speedup=40)
        with Sitl(config) as sitl:
            udp = next(s for s in sitl._sockets if isinstance(s, UdpSocket))
            hb = M.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3).pack(
                new_encoder(sysid=200, compid=1)
            )
            for _ in range(ghosts):  # one HEARTBEAT from each of 2,000 source ports
                with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                    s.sendto(hb, ("127.0.0.1", sitl.ports[1]))
            settle(udp)
            c = Client.tcp(sitl.ports[0])
            try:
                c.wait_for("HEARTBEAT")
                most = len(udp.links)
                t0 = time.perf_counter()
                c.takeoff(10)
                assert c.command(M.MAV_CMD_NAV_LAND).result == M.MAV_RESULT_ACCEPTED
                c.wait_until(
                    lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
                    what="landed",
                )
                took = time.perf_counter() - t0
                assert most <= MAX_UDP_PEERS
                if ghosts:
                    # The rest were refused (or dropped by the kernel's full socket buffer).
                    assert udp.peers_refused > 0
                    c.wait_until(lambda _: not udp.links, what="ghost peers to expire")
                    assert len(sitl.sessions) == 1  # only the TCP ground station is served
            finally:
                c.close()  # else it lingers, and warns in a later test
        assert sitl.error is None
        return took, most

    clean_s, _ = flight(0)
    ghost_s, most = flight(2000)
    logging.getLogger(__name__).warning(
        "flight: %.2f s clean, %.2f s with 2,000 ghost peers (%d served at most)",
        clean_s,
        ghost_s,
        most,
    )
    assert ghost_s < 1.5 * clean_s + 0.5


def test_a_fault_refuses_one_request_and_repeated_faults_drop_only_that_link(
    vehicle: Sitl,
    client: Client,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
    request: pytest.FixtureRequest,
) -> None:
    from uavtool.sitl import commands

    def broken(session: object, cmd: object) -> object:
        raise RuntimeError("a bug in a handler")

    monkeypatch.setitem(commands.HANDLERS, M.MAV_CMD_DO_SET_ROI, broken)
    other = Client.tcp(vehicle.ports[0])
    request.addfinalizer(other.close)  # closed even when an assertion fails
    other.wait_for("HEARTBEAT")
    with caplog.at_level(logging.ERROR, logger="uavtool.sitl.server"):
        ack = client.command(M.MAV_CMD_DO_SET_ROI)
        assert ack.result == M.MAV_RESULT_FAILED
        assert "internal error" in client.reason()
        for _ in range(MAX_LINK_FAULTS):
            client.send(
                M.MAVLink_command_long_message(1, 1, M.MAV_CMD_DO_SET_ROI, 0, 0, 0, 0, 0, 0, 0, 0)
            )
        client.pump(0.5)
    assert vehicle.faults == MAX_LINK_FAULTS  # the 10th dropped the link: no 11th was read
    assert "a bug in a handler" in caplog.text
    # The vehicle and its other client go on.
    assert other.command(ARM, 1).result == M.MAV_RESULT_ACCEPTED
    assert len(vehicle.sessions) == 1


def test_a_message_that_does_not_fit_is_not_sent_and_the_link_goes_on(
    client: Client, vehicle: Sitl
) -> None:
    session = vehicle.sessions[0]
    session.send(M.MAVLink_gimbal_manager_status_message(0, 0, 1, 300, 1, 0, 0))
    assert session.link.unsendable == 1
    assert client.command(M.MAV_CMD_GET_HOME_POSITION).result == M.MAV_RESULT_ACCEPTED


def test_a_signed_ground_station_connecting_late_at_speedup_10_is_answered() -> None:
    # Sim time runs 10x: after 8 s of wall time the vehicle's simulated clock is 72 s ahead
    # of the ground station's, more than the minute a new stream may lag.
    config = SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=10, signing_key=KEY)
    with Sitl(config) as sitl:
        t0 = time.monotonic()
        while sitl.now_ns < 80 * 10**9:
            time.sleep(0.1)
            assert time.monotonic() - t0 < 30, "the vehicle does not run"
        gcs = Client.tcp(sitl.ports[0], signing_key=KEY)
        gcs.wait_for("HEARTBEAT")
        assert gcs.command(ARM, 1).result == M.MAV_RESULT_ACCEPTED
        gcs.close()
        assert sitl.autopilot.armed


def test_the_signing_time_never_goes_backwards_when_the_clock_does() -> None:
    now_us = [1_800_000_000 * 10**6]  # a wall clock the test can set back, as NTP can
    streams = SigningStreams(KEY, unix_us=lambda: now_us[0])

    def signed_at(unix_s: float, link_id: int) -> bytes:
        enc = new_encoder(sysid=255, compid=190, signing_key=KEY, link_id=link_id)
        enc.signing.timestamp = int((unix_s - SIGNING_EPOCH_UNIX_US / 1e6) * 100_000)
        return bytes(M.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3).pack(enc))

    captured = signed_at(1_800_000_000 - 120, link_id=1)  # two minutes old
    assert not streams.verify(captured)
    now_us[0] -= 3600 * 10**6  # the machine's clock steps back an hour
    assert not streams.verify(captured)  # still two minutes older than the vehicle's time
    assert streams.verify(signed_at(1_800_000_000 - 30, link_id=2))  # within the minute
