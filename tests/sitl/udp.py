"""Waiting for the vehicle's UDP socket to have read a flood of datagrams."""

from __future__ import annotations

import time

from uavtool.sitl.links import MAX_UDP_PEERS, UdpSocket


def settle(udp: UdpSocket, *, quiet_s: float = 0.5, within_s: float = 10.0) -> None:
    """Return once ``udp`` has served at most `MAX_UDP_PEERS` peers for ``quiet_s`` on end.

    The vehicle serves each datagram from a new peer at once and bounds its table at its next
    step: right after a flood its table holds more until it has read what the kernel kept
    for it, later on a loaded machine (the suite's other workers) than on an idle one. Raise
    AssertionError if it never settles within ``within_s``."""
    deadline = time.monotonic() + within_s
    calm_since = None
    while time.monotonic() < deadline:
        now = time.monotonic()
        if len(udp.links) > MAX_UDP_PEERS:
            calm_since = None
        elif calm_since is None:
            calm_since = now
        elif now - calm_since >= quiet_s:
            return
        time.sleep(0.02)
    raise AssertionError(f"the vehicle still served {len(udp.links)} UDP peers after {within_s} s")
