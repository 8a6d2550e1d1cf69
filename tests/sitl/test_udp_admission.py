"""Issue 30, item 4: who gets a place among a ``udpin`` endpoint's peers, and whose port it is.

Spoofed sources that write every few seconds, or a flood of new addresses, must not keep a
new ground station out; no other socket may bind the vehicle's UDP port; and traffic must not
make sim time run ahead of the speed-up. Peers are timed in real time, so these run at 1x.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import socket
import threading
import time
from collections.abc import Iterator

import pytest
from click.testing import CliRunner

from tests.sitl.client import Client
from tests.sitl.udp import settle
from uavtool.cli import cli
from uavtool.mavlink import mavlink as M
from uavtool.mavlink import new_encoder
from uavtool.sitl import Sitl, SitlConfig
from uavtool.sitl.links import MAX_UDP_PEERS, UdpSocket

log = logging.getLogger(__name__)
_SPOOF_HB = M.MAVLink_heartbeat_message(M.MAV_TYPE_GCS, 8, 0, 0, 0, 3).pack(
    new_encoder(sysid=200, compid=1)
)


@contextlib.contextmanager
def _vehicle(speedup: float = 1.0) -> Iterator[tuple[Sitl, UdpSocket]]:
    with Sitl(SitlConfig(endpoints=("udpin:127.0.0.1:0",), speedup=speedup)) as sitl:
        yield sitl, next(s for s in sitl._sockets if isinstance(s, UdpSocket))
    assert sitl.error is None


def _udp_gcs(port: int) -> Client:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    return Client(sock, udp_addr=("127.0.0.1", port))


def _fly_gcs(gcs: Client, seconds: float) -> list[float]:
    """Send a HEARTBEAT every second for ``seconds``, as ground stations do; return when
    (seconds since the start) each of the vehicle's HEARTBEATs arrived."""
    t0 = time.monotonic()
    heard: list[float] = []
    next_hb = t0
    while (now := time.monotonic()) < t0 + seconds:
        if now >= next_hb:
            gcs.heartbeat()
            next_hb += 1.0
        heard += [now - t0 for m in gcs.pump(0.02) if m.get_type() == "HEARTBEAT"]
    return heard


def _longest_gap(times: list[float], start: float, end: float) -> float:
    marks = [start, *(t for t in times if start <= t <= end), end]
    return max(b - a for a, b in itertools.pairwise(marks))


def test_sixteen_spoofed_peers_writing_every_5_s_do_not_keep_a_ground_station_out() -> None:
    with _vehicle() as (sitl, udp):
        spoofers = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(16)]
        stop = threading.Event()

        def spoof() -> None:  # all 16 at once every 5 s: the hardest phase for a newcomer
            while not stop.is_set():
                for s in spoofers:
                    s.sendto(_SPOOF_HB, ("127.0.0.1", sitl.ports[0]))
                stop.wait(5.0)

        thread = threading.Thread(target=spoof, daemon=True)
        thread.start()
        time.sleep(0.5)
        assert len(udp.links) == MAX_UDP_PEERS  # the table is full of spoofed peers
        gcs = _udp_gcs(sitl.ports[0])
        try:
            heard = _fly_gcs(gcs, 9.0)  # through the spoofers' next round at 4.5 s
        finally:
            stop.set()
            thread.join()
            gcs.close()
            for s in spoofers:
                s.close()
        log.warning(
            "new ground station among 16 spoofers: first HEARTBEAT after %.2f s, %d in 9 s",
            heard[0] if heard else -1,
            len(heard),
        )
        assert heard, "the ground station got nothing"
        assert heard[0] < 2.0
        assert _longest_gap(heard, heard[0], 9.0) < 2.0  # and it kept its place


def test_a_ground_station_is_answered_at_once_after_a_flood_of_2000_peers() -> None:
    with _vehicle() as (sitl, udp):
        for _ in range(2000):  # one HEARTBEAT from each of 2,000 source ports
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                s.sendto(_SPOOF_HB, ("127.0.0.1", sitl.ports[0]))
        settle(udp)
        assert len(udp.links) == MAX_UDP_PEERS
        gcs = _udp_gcs(sitl.ports[0])
        try:
            heard = _fly_gcs(gcs, 3.0)
        finally:
            gcs.close()
        log.warning("after 2,000 ghosts: first HEARTBEAT after %.2f s", heard[0] if heard else -1)
        assert heard and heard[0] < 1.0
        # Turned away by admission; how many the kernel dropped first depends on the load (385
        # of 2,000 reached the vehicle in one run of the whole suite), so only "some".
        assert udp.peers_refused > 0


def test_a_ground_station_keeps_its_place_through_a_flood_of_new_addresses() -> None:
    with _vehicle() as (sitl, udp):
        stop = threading.Event()
        sent = 0

        def flood() -> None:  # ~400 new source addresses a second
            nonlocal sent
            while not stop.is_set():
                for _ in range(20):
                    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                        s.sendto(_SPOOF_HB, ("127.0.0.1", sitl.ports[0]))
                    sent += 1
                stop.wait(0.05)

        thread = threading.Thread(target=flood, daemon=True)
        thread.start()
        time.sleep(1.0)
        gcs = _udp_gcs(sitl.ports[0])
        try:
            heard = _fly_gcs(gcs, 6.0)
        finally:
            stop.set()
            thread.join()
            gcs.close()
        log.warning(
            "through a flood of %d addresses: first HEARTBEAT after %.2f s, %d in 6 s",
            sent,
            heard[0] if heard else -1,
            len(heard),
        )
        # The flood reached the vehicle (on a loaded machine the kernel drops part of it:
        # 403 of the 1000+ were read in one CI run)
        assert sent > 1000 and udp.peers_refused > 100
        assert heard and heard[0] < 2.0
        # From its second HEARTBEAT on (1 s) it is in steady contact and stays.
        assert _longest_gap(heard, 1.5, 6.0) < 1.5


def test_incoming_traffic_does_not_make_sim_time_run_ahead() -> None:
    with _vehicle() as (sitl, _):
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        t0, sim0 = time.monotonic(), sitl.now_ns
        while time.monotonic() - t0 < 2.0:  # 250 datagrams a second
            sock.sendto(_SPOOF_HB, ("127.0.0.1", sitl.ports[0]))
            time.sleep(0.004)
        wall_s, sim_s = time.monotonic() - t0, (sitl.now_ns - sim0) / 1e9
        sock.close()
    assert sim_s == pytest.approx(wall_s, abs=0.15)  # it ran 9.6 s of sim time in 2 s


def test_no_other_socket_can_bind_the_udpin_port() -> None:
    with _vehicle() as (sitl, _):
        thief = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        thief.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if hasattr(socket, "SO_REUSEPORT"):
            thief.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        with thief, pytest.raises(OSError, match="in use"):
            thief.bind(("127.0.0.1", sitl.ports[0]))


def test_a_second_sitl_on_the_same_udpin_port_is_one_line_exit_2() -> None:
    with _vehicle() as (sitl, _):
        port = sitl.ports[0]
        result = CliRunner().invoke(
            cli, ["sitl", "--endpoint", f"udpin:127.0.0.1:{port}", "--duration", "1"]
        )
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert f"port {port} is in use" in result.output
    assert "choose another port" in result.output
