"""A lossy UDP link for tests: a thread between a ground station and a vehicle that drops,
delays and so reorders datagrams, from a seeded random generator."""

from __future__ import annotations

import heapq
import random
import select
import socket
import threading
import time
from dataclasses import dataclass

_MAX_DATAGRAM = 65535


@dataclass(frozen=True, slots=True)
class Impairment:
    """Each datagram, in either direction, is lost with probability ``loss``; of the others a
    ``delayed`` fraction is held for up to ``max_delay_s`` (uniform) while later ones pass."""

    loss: float = 0.0
    delayed: float = 0.0
    max_delay_s: float = 0.0


class LossyProxy:
    """Listens on ``127.0.0.1:port`` for the ground station (which speaks first) and relays
    to and from the vehicle at ``127.0.0.1:vehicle_port``. ``time_scale`` divides every delay:
    against a vehicle running N× real time, a delay of ``max_delay_s`` of vehicle time is
    ``max_delay_s / N`` of wall time. Counts what it ``forwarded``, ``lost`` and ``held``."""

    def __init__(
        self, vehicle_port: int, impairment: Impairment, *, seed: int, time_scale: float = 1.0
    ) -> None:
        self.impairment = impairment
        self.time_scale = time_scale
        self._rng = random.Random(seed)
        self._front = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._front.bind(("127.0.0.1", 0))
        self._back = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._back.bind(("127.0.0.1", 0))
        self.port: int = self._front.getsockname()[1]
        self._vehicle = ("127.0.0.1", vehicle_port)
        self._gcs: tuple[str, int] | None = None
        self._held: list[tuple[float, int, bool, bytes]] = []  # (due, n, to vehicle?, datagram)
        self._n = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="lossy-proxy", daemon=True)
        self.forwarded = self.lost = self.held = 0

    def __enter__(self) -> LossyProxy:
        self._thread.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self._front.close()
        self._back.close()

    def _run(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            while self._held and self._held[0][0] <= now:
                _, _, to_vehicle, data = heapq.heappop(self._held)
                self._forward(to_vehicle, data)
            wait = min(0.05, self._held[0][0] - now) if self._held else 0.05
            readable, _, _ = select.select([self._front, self._back], [], [], max(wait, 0.0))
            for sock in readable:
                try:
                    data, addr = sock.recvfrom(_MAX_DATAGRAM)
                except OSError:  # an ICMP "port unreachable" from a peer that is not up yet
                    continue
                to_vehicle = sock is self._front
                if to_vehicle:
                    self._gcs = addr
                self._impair(to_vehicle, data)

    def _impair(self, to_vehicle: bool, data: bytes) -> None:
        imp, rng = self.impairment, self._rng
        if rng.random() < imp.loss:
            self.lost += 1
        elif rng.random() < imp.delayed:
            self.held += 1
            self._n += 1
            due = time.monotonic() + rng.uniform(0.0, imp.max_delay_s) / self.time_scale
            heapq.heappush(self._held, (due, self._n, to_vehicle, data))
        else:
            self._forward(to_vehicle, data)

    def _forward(self, to_vehicle: bool, data: bytes) -> None:
        if to_vehicle:
            self._back.sendto(data, self._vehicle)
        elif self._gcs is not None:
            self._front.sendto(data, self._gcs)
        else:
            return
        self.forwarded += 1
