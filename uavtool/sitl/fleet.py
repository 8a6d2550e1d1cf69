"""Several built-in vehicles in one world: one clock, one physics step for all, and contact
between them.

Each vehicle is a whole :class:`~uavtool.sitl.server.Sitl` — its own autopilot, parameters,
MAVLink links, system id and ports (``instance``: ports +10 and sysid +1 per vehicle, as
ArduPilot's ``-I``) — and the fleet steps them together: every vehicle advances one physics
step, then the fleet judges contact between their bodies, then each vehicle sends what is due.
So vehicle 2 never runs ahead of vehicle 1, and two that touch are both ``crashed`` in the
step they touch, as a vehicle that touches a building is.

Where the vehicles stand: the first at its home, the others on a line from it, ``spacing_m``
apart along ``bearing_deg`` (:class:`OffsetLine`, the rule of ArduPilot's
``sim_vehicle.py --count N --auto-offset-line 90,10``), or each at a home of its own.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import selectors
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from uavtool.errors import InputError
from uavtool.geo import GeoPoint, enu_from_geo, geo_from_enu
from uavtool.sitl.config import SitlConfig
from uavtool.sitl.links import FrameTap
from uavtool.sitl.obstacles import ObstacleField, Prism
from uavtool.sitl.server import Sitl, serve_paced

_NS = 1_000_000_000
MAX_VEHICLES = 64
"""More vehicles than this in one world are refused (ports +10 each: 64 reach 6390 above the
first's)."""


@dataclass(frozen=True, slots=True)
class OffsetLine:
    """Vehicle ``i`` stands ``i × spacing_m`` from the first, along ``bearing_deg`` (degrees
    from north, clockwise)."""

    bearing_deg: float = 90.0
    spacing_m: float = 10.0

    def __post_init__(self) -> None:
        if not math.isfinite(self.bearing_deg):
            raise InputError(f"offset line bearing {self.bearing_deg}: must be finite")
        if not (0.0 < self.spacing_m <= 1000.0):
            raise InputError(f"offset line spacing {self.spacing_m:g} m: must be in (0, 1000] m")

    def __str__(self) -> str:
        return f"{self.bearing_deg:g},{self.spacing_m:g}"


def parse_offset_line(text: str) -> OffsetLine:
    """``BEARING,SPACING`` (degrees, metres), e.g. ``90,10``."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        bearing, spacing = (float(p) for p in parts)
    except ValueError:
        raise InputError(
            f"offset line {text!r}: expected BEARING,SPACING in degrees and metres, e.g. 90,10"
        ) from None
    return OffsetLine(bearing, spacing)


def line_homes(first: GeoPoint, count: int, line: OffsetLine) -> tuple[GeoPoint, ...]:
    """The homes of ``count`` vehicles on ``line`` from ``first`` (all at its altitude)."""
    b = math.radians(line.bearing_deg)
    east, north = math.sin(b), math.cos(b)
    return tuple(
        geo_from_enu(first, i * line.spacing_m * east, i * line.spacing_m * north, 0.0)
        for i in range(count)
    )


AUTO_BEARINGS_DEG = (90.0, 270.0, 0.0, 180.0, 45.0, 135.0, 225.0, 315.0)
"""The bearings an automatic offset line tries, in order: ArduPilot's east first."""


def clear_line(
    first: GeoPoint,
    count: int,
    obstacles_for: Callable[[GeoPoint], tuple[Prism, ...]],
    *,
    spacing_m: float,
    clear_m: float,
) -> OffsetLine | None:
    """The first offset line (of :data:`AUTO_BEARINGS_DEG`, ``spacing_m`` apart) whose every
    home lies at least ``clear_m`` from every obstacle, None when none does."""
    for bearing in AUTO_BEARINGS_DEG:
        line = OffsetLine(bearing, spacing_m)
        if all(
            ObstacleField(obstacles_for(home)).nearest(0.0, 0.0, 0.0)[0] >= clear_m
            for home in line_homes(first, count, line)[1:]
        ):
            return line
    return None


def vehicle_seed(seed: int, index: int) -> int:
    """The seed of vehicle ``index``'s gusts and sensor noise. The first keeps the flight's own
    (a fleet of one flies as one vehicle does); each other draws from a seed derived from both,
    so that no two vehicles of a flight, and no two flights of a sweep over seeds, share one."""
    if index == 0:
        return seed
    digest = hashlib.blake2b(f"{seed}/{index}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "big")


def fleet_configs(
    base: SitlConfig,
    homes: Sequence[GeoPoint],
    *,
    obstacles_for: Callable[[GeoPoint], tuple[Prism, ...]] | None = None,
) -> tuple[SitlConfig, ...]:
    """One configuration per home: ``base`` as vehicle ``base.instance + i`` (its ports and
    sysid offset), its own seed (:func:`vehicle_seed`) and, with ``obstacles_for``, the world's
    obstacles in the frame of its home (e.g. ``lambda h: scene_obstacles(scene, home=h)``)."""
    if not 1 <= len(homes) <= MAX_VEHICLES:
        raise InputError(f"{len(homes)} vehicles: a fleet has 1 to {MAX_VEHICLES}")
    return tuple(
        dataclasses.replace(
            base,
            home=home,
            instance=base.instance + i,
            seed=vehicle_seed(base.seed, i),
            obstacles=base.obstacles if obstacles_for is None else obstacles_for(home),
        )
        for i, home in enumerate(homes)
    )


@dataclass(frozen=True, slots=True)
class Approach:
    """The least distance between two vehicles so far, while at least one of them was off
    the ground: between their positions (``distance_m``) and between their bodies (``gap_m``;
    ≤ 0: they touched), and which two (system ids)."""

    distance_m: float = math.inf
    gap_m: float = math.inf
    sysids: tuple[int, int] = (0, 0)
    at_ns: int = 0
    """Vehicle time when it was measured."""


class Fleet:
    """The vehicles of ``configs`` in one world (their homes, obstacles and links as each
    config says; see :func:`fleet_configs`). Step it (:meth:`step`) in a program, or serve it
    on the wall clock (:meth:`run`, or as a context manager in a thread, as :class:`Sitl`)."""

    def __init__(self, configs: Sequence[SitlConfig], *, frame_tap: FrameTap | None = None):
        if not 1 <= len(configs) <= MAX_VEHICLES:
            raise InputError(f"{len(configs)} vehicles: a fleet has 1 to {MAX_VEHICLES}")
        sysids = [c.sysid + c.instance for c in configs]
        if len(set(sysids)) != len(sysids):
            raise InputError(f"system ids {sysids}: every vehicle of a fleet needs its own")
        origin = configs[0].home
        self.offsets_enu_m = tuple(enu_from_geo(origin, c.home) for c in configs)
        """Each vehicle's home in the fleet's frame (ENU metres around the first's home)."""
        _check_homes(configs, self.offsets_enu_m, sysids)
        self._waiter: selectors.BaseSelector | None = None
        self._naps = False  # no selector to wait on every vehicle's sockets at once
        self.vehicles: list[Sitl] = []
        try:
            for config in configs:
                self.vehicles.append(Sitl(config, frame_tap=frame_tap))
        except Exception:
            self.close()
            raise
        rates = {v.dt_ns for v in self.vehicles}
        if len(rates) != 1:
            self.close()
            raise InputError("every vehicle of a fleet needs the same SIM_RATE_HZ")
        self.dt_ns = rates.pop()
        self.speedup = min(v.speedup for v in self.vehicles)
        self.approach = Approach()
        """The closest two vehicles have come (:class:`Approach`)."""
        self.contacts: list[tuple[int, int, int]] = []
        """Every contact: (vehicle time ns, sysid, sysid)."""
        self._previous = self._positions()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None

    # ------------------------------------------------------------------ the world
    @property
    def now_ns(self) -> int:
        """The world's time: every vehicle's."""
        return self.vehicles[0].now_ns

    @property
    def sysids(self) -> tuple[int, ...]:
        return tuple(v.sysid for v in self.vehicles)

    def step(self) -> None:
        """One physics step of every vehicle, contact between them judged, then what each has
        to say sent."""
        for vehicle in self.vehicles:
            vehicle.advance()
        self._judge_contacts()
        for vehicle in self.vehicles:
            vehicle.publish()

    def _positions(self) -> list[tuple[float, float, float]]:
        out = []
        for vehicle, (oe, on, ou) in zip(self.vehicles, self.offsets_enu_m, strict=True):
            n, e, d = vehicle.autopilot.vehicle.state.pos_ned_m
            out.append((oe + e, on + n, ou - d))
        return out

    def _judge_contacts(self) -> None:
        """The least gap of every pair over the step just taken (their motion in it taken as
        straight: fast vehicles cannot pass through each other between two steps), and a crash
        for both of a pair whose bodies met while one of them was off the ground."""
        now = self._positions()
        before, self._previous = self._previous, now
        vehicles = self.vehicles
        for i in range(len(vehicles)):
            a = vehicles[i]
            a_air = not a.autopilot.vehicle.state.on_ground
            for j in range(i + 1, len(vehicles)):
                b = vehicles[j]
                if not (a_air or not b.autopilot.vehicle.state.on_ground):
                    continue
                distance_m = _swept_distance(before[i], now[i], before[j], now[j])
                gap_m = distance_m - (a.config.body_radius_m + b.config.body_radius_m)
                if gap_m < self.approach.gap_m:
                    self.approach = Approach(distance_m, gap_m, (a.sysid, b.sysid), a.now_ns)
                if gap_m < 0.0:
                    self._contact(a, b)

    def _contact(self, a: Sitl, b: Sitl) -> None:
        self.contacts.append((a.now_ns, a.sysid, b.sysid))
        for vehicle, other in ((a, b), (b, a)):
            if not vehicle.crashed:
                vehicle.autopilot.crash(f"Crash: collision with vehicle {other.sysid}")

    # ------------------------------------------------------------------ serving
    def poll(self, timeout_s: float) -> None:
        """Serve every vehicle's sockets for up to ``timeout_s`` (0: what is waiting)."""
        if timeout_s > 0.0:
            self._wait(timeout_s)
        for vehicle in self.vehicles:
            vehicle.poll(0.0)

    def _wait(self, timeout_s: float) -> None:
        if self._waiter is None and not self._naps:
            fds = [vehicle.fileno() for vehicle in self.vehicles]
            if any(fd is None for fd in fds):
                self._naps = True
            else:
                self._waiter = selectors.DefaultSelector()
                for fd in fds:
                    assert fd is not None
                    self._waiter.register(fd, selectors.EVENT_READ)
        if self._waiter is None:
            time.sleep(min(timeout_s, 0.001))
        else:
            self._waiter.select(timeout_s)

    def run(self, *, duration_s: float | None = None) -> None:
        """Serve the fleet in this thread, paced by the wall clock at the slowest vehicle's
        ``SIM_SPEEDUP``, until :meth:`stop` (or for ``duration_s`` of sim time)."""
        end_ns = None if duration_s is None else self.now_ns + int(duration_s * _NS)
        serve_paced(
            step=self.step,
            poll=self.poll,
            now_ns=lambda: self.now_ns,
            speedup=self._slowest,
            vehicles=self.vehicles,
            stop=self._stop,
            end_ns=end_ns,
        )

    def _slowest(self) -> float:
        self.speedup = min(v.speedup for v in self.vehicles)
        return self.speedup

    def start(self) -> Fleet:
        """Serve in a daemon thread; returns self."""
        self._thread = threading.Thread(target=self._run_guarded, name="sitl-fleet", daemon=True)
        self._thread.start()
        return self

    def _run_guarded(self) -> None:
        try:
            self.run()
        except BaseException as exc:
            self.error = exc

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
        self.close()

    def close(self) -> None:
        if self._waiter is not None:
            self._waiter.close()
        self._waiter = None
        for vehicle in self.vehicles:
            vehicle.close()

    def __enter__(self) -> Fleet:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _swept_distance(
    a0: tuple[float, float, float],
    a1: tuple[float, float, float],
    b0: tuple[float, float, float],
    b1: tuple[float, float, float],
) -> float:
    """The least distance between two points moving straight from ``a0``/``b0`` to
    ``a1``/``b1`` over the same interval."""
    r0 = (a0[0] - b0[0], a0[1] - b0[1], a0[2] - b0[2])
    dr = (a1[0] - b1[0] - r0[0], a1[1] - b1[1] - r0[1], a1[2] - b1[2] - r0[2])
    dd = dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2]
    t = 1.0
    if dd > 0.0:
        t = min(max(-(r0[0] * dr[0] + r0[1] * dr[1] + r0[2] * dr[2]) / dd, 0.0), 1.0)
    return math.dist((r0[0] + t * dr[0], r0[1] + t * dr[1], r0[2] + t * dr[2]), (0.0, 0.0, 0.0))


def _check_homes(
    configs: Sequence[SitlConfig],
    offsets: Sequence[tuple[float, float, float]],
    sysids: Sequence[int],
) -> None:
    """Refuse homes where a vehicle stands inside a building or on another vehicle."""
    for i, config in enumerate(configs):
        radius = config.body_radius_m
        if config.obstacles:
            distance_m, prism = ObstacleField(config.obstacles).nearest(0.0, 0.0, radius)
            if prism is not None and distance_m < radius:
                home = config.home
                raise InputError(
                    f"vehicle {sysids[i]}'s home {home.lat_deg:.6f},{home.lon_deg:.6f} is in "
                    f"building {prism.name!r}: give the fleet other homes (another offset line, "
                    "or a home per vehicle)"
                )
        for j in range(i):
            apart_m = math.dist(offsets[i], offsets[j])
            if apart_m < radius + configs[j].body_radius_m:
                raise InputError(
                    f"vehicles {sysids[j]} and {sysids[i]} stand {apart_m:.2f} m apart, less "
                    "than their bodies: give the fleet homes farther apart"
                )
