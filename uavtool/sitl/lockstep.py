"""Lockstep: the built-in vehicle stepped by its one client, so that a flight is a function of
its inputs — not of the machine's speed or load.

The vehicle's clock advances only inside :meth:`LockstepTransport.recv`, that is only when its
client asks for more: by then the client has consumed everything the vehicle sent so far. And
before every step the vehicle first takes in everything the client sent. The bytes still cross
the vehicle's MAVLink link (its parser, encoder and ground-station session) and the client's
(:mod:`uavtool.link`); only the socket between them is replaced by two byte buffers.

PX4's and ArduPilot's lockstep covers the simulator and the autopilot but not the ground-station
link, so their SITL tests still depend on timing; here the whole loop is stepped. A client that
is not ours (MAVProxy, QGroundControl) cannot be stepped: ``uavtool sitl`` stays wall-paced.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from uavtool.camera import CameraPose
from uavtool.sitl.config import SitlConfig
from uavtool.sitl.fleet import Fleet
from uavtool.sitl.mount import true_camera_pose
from uavtool.sitl.server import Sitl

_NS = 1_000_000_000
SIM_EPOCH_UNIX_S = 1_767_225_600
"""2026-01-01T00:00:00Z: the wall-clock date a simulated vehicle boots at, and the origin of
a simulated flight's recording clock (``log_time = SIM_EPOCH + vehicle time since boot``)."""
SIM_EPOCH_NS = SIM_EPOCH_UNIX_S * _NS


class LockstepTransport:
    """A :class:`uavtool.link.transport.Transport` to an in-process :class:`Sitl` that steps it.

    ``recv(timeout_s)`` returns what the vehicle has sent; when nothing is waiting it delivers
    the client's bytes and steps the vehicle until it says something or ``timeout_s`` of
    *vehicle* time has passed. ``speedup`` caps the pace (vehicle seconds per wall second);
    None runs as fast as the CPU allows. The pace never changes what is computed.
    """

    def __init__(self, config: SitlConfig, *, speedup: float | None = None) -> None:
        if speedup is not None and not speedup > 0:
            raise ValueError(f"speedup must be > 0 or None, got {speedup}")
        self.name = "lockstep:builtin"
        self.vehicle = Sitl(config)
        self.speedup = speedup
        self._to_client = bytearray()
        self._to_vehicle = bytearray()
        self._link = self.vehicle.attach(self.name, self._to_client.extend)
        self._wall0: float | None = None
        self._sim0_ns = 0

    # --- the clock -----------------------------------------------------------------------------

    def clock(self) -> float:
        """Vehicle time since boot, seconds: the only clock a lockstep flight has."""
        return self.vehicle.now_ns / _NS

    def recording_ns(self) -> int:
        """The recording clock: :data:`SIM_EPOCH_NS` plus vehicle time since boot."""
        return SIM_EPOCH_NS + self.vehicle.now_ns

    def camera_pose(self) -> CameraPose:
        """Where the vehicle's camera really is at this instant, in ENU metres around its home:
        a simulated camera photographs the world from here, not from the pose the telemetry
        last reported (which lags, and carries the GPS noise a real one would)."""
        ap = self.vehicle.autopilot
        return true_camera_pose(ap.state, ap.gimbal, ap.mount)

    # --- Transport -----------------------------------------------------------------------------

    def send(self, data: bytes) -> None:
        self._to_vehicle += data

    def recv(self, timeout_s: float) -> bytes:
        deadline_ns = self.vehicle.now_ns + max(round(timeout_s * _NS), 0)
        while True:
            self._deliver()
            if self._to_client:
                data = bytes(self._to_client)
                self._to_client.clear()
                return data
            if self.vehicle.now_ns >= deadline_ns:
                return b""
            self._pace()
            self.vehicle.step()

    def close(self) -> None:
        self._link.closed = True
        self.vehicle.close()

    # --- internals -----------------------------------------------------------------------------

    def _deliver(self) -> None:
        if self._to_vehicle:
            data = bytes(self._to_vehicle)
            self._to_vehicle.clear()
            self.vehicle.deliver(self._link, data)

    def _pace(self) -> None:
        if self.speedup is None:
            return
        now = time.perf_counter()
        if self._wall0 is None:
            self._wall0, self._sim0_ns = now, self.vehicle.now_ns
            return
        due = self._wall0 + (self.vehicle.now_ns - self._sim0_ns) / _NS / self.speedup
        if due > now:
            time.sleep(due - now)


class FleetLockstep:
    """Several built-in vehicles in one world (:class:`~uavtool.sitl.fleet.Fleet`), stepped by
    their clients: the fleet's flight is a function of its inputs, as one vehicle's is.

    ``members[i]`` is vehicle ``i``'s :class:`~uavtool.link.transport.Transport`. Its
    ``recv(timeout_s)`` returns what the vehicle has sent; with nothing waiting and a timeout,
    it steps the whole world until the vehicle speaks (how each client connects, one after
    another). A loop that serves every vehicle reads them with ``recv(0)``, which never steps,
    and steps the world itself (:meth:`step_until_said`).
    """

    def __init__(self, configs: Sequence[SitlConfig], *, speedup: float | None = None) -> None:
        if speedup is not None and not speedup > 0:
            raise ValueError(f"speedup must be > 0 or None, got {speedup}")
        self.fleet = Fleet(configs)
        self.speedup = speedup
        self.members = [_Member(self, vehicle) for vehicle in self.fleet.vehicles]
        self._wall0: float | None = None
        self._sim0_ns = 0

    def clock(self) -> float:
        """The world's time since boot, seconds: every vehicle's."""
        return self.fleet.now_ns / _NS

    def recording_ns(self) -> int:
        return SIM_EPOCH_NS + self.fleet.now_ns

    def camera_pose(self, index: int) -> CameraPose:
        """Where vehicle ``index``'s camera really is (ENU around its own home)."""
        ap = self.fleet.vehicles[index].autopilot
        return true_camera_pose(ap.state, ap.gimbal, ap.mount)

    def step(self) -> None:
        """Every client's bytes delivered, then one physics step of the world."""
        for member in self.members:
            member.deliver()
        self._pace()
        self.fleet.step()

    def step_until_said(self, timeout_s: float) -> None:
        """Deliver every client's bytes, then step until a vehicle has said something to its
        client or ``timeout_s`` of world time has passed."""
        deadline_ns = self.fleet.now_ns + max(round(timeout_s * _NS), 0)
        while True:
            for member in self.members:
                member.deliver()
            if any(m.waiting for m in self.members) or self.fleet.now_ns >= deadline_ns:
                return
            self._pace()
            self.fleet.step()

    def close(self) -> None:
        for member in self.members:
            member.closed = True
        self.fleet.close()

    def _pace(self) -> None:
        if self.speedup is None:
            return
        now = time.perf_counter()
        if self._wall0 is None:
            self._wall0, self._sim0_ns = now, self.fleet.now_ns
            return
        due = self._wall0 + (self.fleet.now_ns - self._sim0_ns) / _NS / self.speedup
        if due > now:
            time.sleep(due - now)


class _Member:
    """One vehicle's end of a :class:`FleetLockstep`."""

    def __init__(self, world: FleetLockstep, vehicle: Sitl) -> None:
        self.world = world
        self.vehicle = vehicle
        self.name = f"lockstep:builtin:{vehicle.sysid}"
        self._to_client = bytearray()
        self._to_vehicle = bytearray()
        self._link = vehicle.attach(self.name, self._received)
        self.closed = False
        """Set when the client is done: what the vehicle says from then on is dropped."""

    @property
    def waiting(self) -> bool:
        """Whether the vehicle has said something its client has not read."""
        return bool(self._to_client)

    def _received(self, data: bytes) -> None:
        if not self.closed:
            self._to_client += data

    def deliver(self) -> None:
        if self._to_vehicle:
            data = bytes(self._to_vehicle)
            self._to_vehicle.clear()
            self.vehicle.deliver(self._link, data)

    def send(self, data: bytes) -> None:
        self._to_vehicle += data

    def recv(self, timeout_s: float) -> bytes:
        world = self.world
        deadline_ns = world.fleet.now_ns + max(round(timeout_s * _NS), 0)
        while True:
            self.deliver()
            if self._to_client:
                data = bytes(self._to_client)
                self._to_client.clear()
                return data
            if world.fleet.now_ns >= deadline_ns:
                return b""
            world.step()

    def close(self) -> None:
        self.closed = True
        self._to_client.clear()
