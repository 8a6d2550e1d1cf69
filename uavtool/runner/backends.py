"""Where the vehicle is: the built-in one in lockstep, or any other over MAVLink. The runner
asks a backend for what differs between them — the link, the clocks, where the simulated
camera really is, how often to send commands again, where the scene's origin goes, how close
the vehicle came to a building — and never looks at the connection string itself."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Protocol

from uavtool.camera import CameraPose
from uavtool.geo import GeoPoint
from uavtool.link import Clock, Transport, open_transport
from uavtool.runner.evaluate import closest_clearance
from uavtool.runner.placement import place_scene
from uavtool.runner.runner import RunnerConfig
from uavtool.world import Scene

if TYPE_CHECKING:
    from uavtool.runner.fly import FlyConfig
    from uavtool.runner.record import ClockNs

BOOT_ONLY_PARAMS = frozenset({"MNT1_TYPE"})
"""Parameters ArduPilot reads at boot only: the built-in vehicle boots with them."""


class Backend(Protocol):
    transport: Transport
    clock: Clock
    """The runner's clock for silence and heartbeats (the vehicle's own in lockstep)."""
    clock_ns: ClockNs
    """Log time of the recording's messages."""
    true_pose: Callable[[], CameraPose] | None
    """Where a simulated camera really is (None: photos come from where telemetry says)."""
    announce: bool
    """Whether to send our heartbeat before the vehicle's first."""
    runner_config: RunnerConfig
    builtin: bool

    def scene_origin(self, scene: Scene, home: GeoPoint, say: Callable[[str], None]) -> GeoPoint:
        """Where the simulated camera's scene lies on the Earth."""
        ...

    def clearance(
        self, route: Sequence[tuple[float, float, float]], scene: Scene, offset: tuple[float, float]
    ) -> tuple[float, str]:
        """Least gap between the vehicle's body and a building, and that building."""
        ...


_NO_RESENDS = RunnerConfig()
_RESENDS = RunnerConfig(command_resend_s=1.0, target_resend_s=1.0)


class BuiltinBackend:
    """The built-in vehicle, in lockstep with the runner: the flight is a function of its
    configuration, and its clearance is the simulator's own, exact."""

    announce = False  # it speaks first; announcing ourselves would change its recordings
    runner_config = _NO_RESENDS  # lockstep loses nothing (and its recordings stay as they are)
    builtin = True

    def __init__(self, lockstep: LockstepTransport) -> None:
        self.lockstep = lockstep

    @property
    def transport(self) -> Transport:
        return self.lockstep

    @property
    def clock(self) -> Clock:
        return self.lockstep.clock

    @property
    def clock_ns(self) -> ClockNs:
        return self.lockstep.recording_ns

    @property
    def true_pose(self) -> Callable[[], CameraPose] | None:
        return self.lockstep.camera_pose

    def scene_origin(self, scene: Scene, home: GeoPoint, say: Callable[[str], None]) -> GeoPoint:
        return scene.home  # it boots at the scene's home

    def clearance(
        self, route: Sequence[tuple[float, float, float]], scene: Scene, offset: tuple[float, float]
    ) -> tuple[float, str]:
        return self.lockstep.vehicle.closest_clearance_m, self.lockstep.vehicle.closest_obstacle


class ExternalBackend:
    """Any other vehicle over MAVLink, on the wall clock. A real link may lose a command, its
    ACK or a position target: they are sent again each second."""

    announce = True
    runner_config = _RESENDS
    builtin = False
    true_pose: Callable[[], CameraPose] | None = None

    def __init__(self, transport: Transport, placement: str) -> None:
        self.transport = transport
        self.placement = placement
        self.clock: Clock = time.monotonic
        self.clock_ns: ClockNs = time.time_ns

    def scene_origin(self, scene: Scene, home: GeoPoint, say: Callable[[str], None]) -> GeoPoint:
        return place_scene(scene, home, self.placement, say)

    def clearance(
        self, route: Sequence[tuple[float, float, float]], scene: Scene, offset: tuple[float, float]
    ) -> tuple[float, str]:
        return closest_clearance(route, scene, body_radius_m=body_radius_m(), offset_en=offset)


@contextmanager
def open_backend(
    config: FlyConfig, scene: Scene, say: Callable[[str], None]
) -> Iterator[BuiltinBackend | ExternalBackend]:
    """The built-in vehicle (``config.connect`` None), or a connection to another."""
    if config.connect is not None:
        transport = open_transport(config.connect, timeout_s=config.connect_timeout_s, waiting=say)
        try:
            yield ExternalBackend(transport, config.scene_origin)
        finally:
            transport.close()
        return
    from uavtool.sitl.lockstep import LockstepTransport  # noqa: PLC0415 - only to simulate
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    sitl_config = builtin_sitl_config(config, scene, obstacles=scene_obstacles(scene))
    lockstep = LockstepTransport(sitl_config, speedup=config.speedup)
    pace = "as fast as it can" if config.speedup is None else f"≤ {config.speedup:g}x"
    say(f"built-in SITL in lockstep ({pace}), scene {scene.name!r}")
    try:
        yield BuiltinBackend(lockstep)
    finally:
        lockstep.close()


def builtin_sitl_config(config: FlyConfig, scene: Scene, *, obstacles: Any) -> SitlConfig:
    """How ``fly`` boots a built-in vehicle at the scene's home: with a servo mount
    (ArduCopter's default has none) holding its nose on the way (WP_YAW_BEHAVIOR 0: the
    mission photographs from known headings), its wind, seed and link faults, among
    ``obstacles``; its clock starts at the simulation's epoch."""
    from uavtool.sitl import SitlConfig  # noqa: PLC0415 - a real vehicle needs no simulator
    from uavtool.sitl.lockstep import SIM_EPOCH_UNIX_S  # noqa: PLC0415

    mount = 0.0 if config.no_gimbal else 1.0
    boot: tuple[tuple[str, float], ...] = (("MNT1_TYPE", mount), ("WP_YAW_BEHAVIOR", 0.0))
    boot += tuple((n, v) for n, v in config.vehicle_params if n in BOOT_ONLY_PARAMS)
    return SitlConfig(
        params=boot,
        endpoints=(),
        obstacles=obstacles,
        home=scene.home,
        home_heading_deg=scene.home_heading_deg,
        seed=config.seed,
        wind_speed_ms=config.wind[0],
        wind_dir_deg=config.wind[1],
        link_outages_s=config.link_outages_s,
        start_unix_us=SIM_EPOCH_UNIX_S * 1_000_000,
    )


def body_radius_m() -> float:
    from uavtool.sitl import SitlConfig  # noqa: PLC0415 - the simulator's default body

    return SitlConfig().body_radius_m


if TYPE_CHECKING:
    from uavtool.sitl.config import SitlConfig
    from uavtool.sitl.lockstep import LockstepTransport
