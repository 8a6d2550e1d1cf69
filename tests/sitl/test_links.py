"""Transports, signing and the sim clock."""

from __future__ import annotations

import socket
import time

import pytest

from tests.sitl.client import Client
from uavtool.errors import LinkError
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl, SitlConfig
from uavtool.sitl.links import parse_endpoint

KEY = bytes(range(32))


def test_udpin_replies_to_the_sender() -> None:
    with Sitl(SitlConfig(endpoints=("udpin:127.0.0.1:0",), speedup=20)) as sitl:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        c = Client(sock, udp_addr=("127.0.0.1", sitl.ports[0]))
        c.heartbeat()
        c.wait_for("HEARTBEAT")
        assert c.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        c.close()


def test_udpout_sends_to_a_listening_ground_station() -> None:
    gcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    gcs.bind(("127.0.0.1", 0))
    port = gcs.getsockname()[1]
    with Sitl(SitlConfig(endpoints=(f"udpout:127.0.0.1:{port}",), speedup=20)):
        c = Client(gcs)
        hb = c.wait_for("HEARTBEAT", timeout=5)
        assert hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
        c.close()


def test_two_vehicles_side_by_side() -> None:
    with (
        Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20)) as a,
        Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20, instance=1)) as b,
    ):
        ca, cb = Client.tcp(a.ports[0]), Client.tcp(b.ports[0])
        assert ca.wait_for("HEARTBEAT").get_srcSystem() == 1
        assert cb.wait_for("HEARTBEAT").get_srcSystem() == 2
        assert (
            cb.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1, target=(2, 1)).result
            == M.MAV_RESULT_ACCEPTED
        )
        ca.close()
        cb.close()


@pytest.mark.parametrize(
    "text", ["tcpin:127.0.0.1", "serial:/dev/ttyUSB0:57600", "udpin:127.0.0.1:99999", "tcp::5"]
)
def test_bad_endpoint_strings(text: str) -> None:
    with pytest.raises(LinkError, match="endpoint"):
        parse_endpoint(text)


def test_port_in_use_is_a_clear_error() -> None:
    with (
        Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",))) as a,
        pytest.raises(LinkError, match="cannot listen"),
    ):
        Sitl(SitlConfig(endpoints=(f"tcpin:127.0.0.1:{a.ports[0]}",)))


def test_signing_refuses_unsigned_commands() -> None:
    with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20, signing_key=KEY)) as sitl:
        unsigned = Client.tcp(sitl.ports[0])
        hb = unsigned.wait_for("HEARTBEAT")
        assert (
            unsigned.frames[-1].raw[2] & M.MAVLINK_IFLAG_SIGNED
        )  # the vehicle signs what it sends
        assert hb is not None
        unsigned.send(M.MAVLink_command_long_message(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0))
        unsigned.pump(0.3)
        assert not any(m.get_type() == "COMMAND_ACK" for m in unsigned.received)
        signed = Client.tcp(sitl.ports[0], signing_key=KEY)
        signed.wait_for("HEARTBEAT")
        assert signed.frames[-1].signed  # its signature verifies with our key
        assert signed.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        wrong = Client.tcp(sitl.ports[0], signing_key=bytes(32))
        wrong.send(M.MAVLink_command_long_message(1, 1, 400, 0, 0, 21196, 0, 0, 0, 0, 0))
        wrong.pump(0.3)
        assert not any(m.get_type() == "COMMAND_ACK" for m in wrong.received)
        for c in (unsigned, signed, wrong):
            c.close()


def _flight(speedup: float) -> list[tuple[float, ...]]:
    """Fly a script of commands delivered at fixed sim times, paced at ``speedup``.

    Steps are driven the way ``Sitl.run`` drives them (step, then wait for the wall clock);
    only the pacing differs between calls, so the paths must be identical.
    """
    from uavtool.mavlink import new_encoder

    enc = new_encoder(sysid=255, compid=190)
    script = {
        1.0: M.MAVLink_command_long_message(1, 1, 176, 0, 1, 4, 0, 0, 0, 0, 0),
        1.5: M.MAVLink_command_long_message(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0),
        2.0: M.MAVLink_command_long_message(1, 1, 22, 0, 0, 0, 0, 0, 0, 0, 15),
        12.0: M.MAVLink_set_position_target_local_ned_message(
            0, 1, 1, 1, 0b110111111000, 40, 25, -20, 0, 0, 0, 0, 0, 0, 0, 0
        ),
        20.0: M.MAVLink_command_long_message(1, 1, 115, 0, 120, 30, 1, 0, 0, 0, 0),
        30.0: M.MAVLink_command_long_message(1, 1, 20, 0, 0, 0, 0, 0, 0, 0, 0),
    }
    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0",),
        speedup=speedup,
        wind_speed_ms=6,
        wind_dir_deg=200,
        seed=7,
        params=(("SIM_WIND_TURB", 1.5),),
    )
    sitl = Sitl(config)
    # A loopback peer that the vehicle serves like any other; we drive the clock ourselves.
    peer = socket.create_connection(("127.0.0.1", sitl.ports[0]))
    path = []
    try:
        sitl.poll(0.1)

        wall0 = time.perf_counter()
        while sitl.now_ns < 60 * 10**9:
            t = round(sitl.now_ns / 1e9, 3)
            if t in script:
                peer.sendall(script[t].pack(enc))
                enc.seq += 1
                sitl.poll(0.05)  # deliver it before this step, whatever the wall clock says
            sitl.step()
            s = sitl.autopilot.state
            path.append((*s.pos_ned_m, s.yaw_deg))
            due = wall0 + sitl.now_ns / 1e9 / speedup
            delay = due - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
    finally:
        peer.close()
        sitl.close()
    return path


@pytest.mark.slow
def test_speedup_does_not_change_the_trajectory() -> None:
    fast = _flight(1e9)
    slow = _flight(50.0)
    assert fast == slow  # bit-identical positions at every physics step
    assert min(p[2] for p in fast) < -14  # it did fly
