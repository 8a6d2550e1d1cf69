"""Where a fleet flies: built-in vehicles in one lockstep world, or external vehicles (ArduPilot's
or PX4's SITL instances, real drones) each on a link of its own, on the wall clock. The fleet's
runner asks a world for what differs — the links, the clocks, where a simulated camera really
is, how to turn the runners, how close the vehicles came — as one vehicle's runner asks a
backend (:mod:`uavtool.runner.backends`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from uavtool.link import Transport, open_transport
from uavtool.mission import Outcome
from uavtool.runner.backends import body_radius_m
from uavtool.runner.evaluate import closest_clearance
from uavtool.runner.runner import Runner, RunnerConfig
from uavtool.world import Scene

if TYPE_CHECKING:
    from uavtool.camera import CameraPose
    from uavtool.sitl.config import SitlConfig
    from uavtool.sitl.lockstep import FleetLockstep

_RESENDS = RunnerConfig(command_resend_s=1.0, target_resend_s=1.0)


class BuiltinWorld:
    """Built-in vehicles in lockstep: the fleet's flight is a function of its inputs."""

    announce = False
    runner_config = RunnerConfig()
    builtin = True

    def __init__(self, configs: Sequence[SitlConfig], *, speedup: float | None) -> None:
        from uavtool.sitl.lockstep import FleetLockstep  # noqa: PLC0415 - only to simulate

        self.lockstep: FleetLockstep = FleetLockstep(configs, speedup=speedup)
        self.transports: list[Transport] = list(self.lockstep.members)
        self.clock = self.lockstep.clock
        self.clock_ns = self.lockstep.recording_ns

    def true_pose(self, index: int) -> Callable[[], CameraPose] | None:
        lockstep = self.lockstep
        return lambda: lockstep.camera_pose(index)

    def run(self, runners: list[Runner]) -> list[Outcome]:
        """Turn every runner until each mission is done; step the world when none has
        anything left to read or feed."""
        for runner in runners:
            runner.begin()
        done = [False] * len(runners)
        poll_s = runners[0].config.poll_s
        while True:
            for i, runner in enumerate(runners):
                if not done[i] and runner.turn(0.0):
                    done[i] = True
                    self.lockstep.members[i].close()  # what it says from now on is nobody's
            if all(done):
                return [r.finish() for r in runners]
            if any(r.busy for i, r in enumerate(runners) if not done[i]):
                continue
            self.lockstep.step_until_said(poll_s)

    def approach(self) -> tuple[float, tuple[int, int]]:
        """The least distance between two vehicles (positions), and which two (sysids)."""
        a = self.lockstep.fleet.approach
        return a.distance_m, a.sysids

    def clearance(self, index: int, runner: Runner, scene: Scene) -> float | None:  # noqa: ARG002
        value = self.lockstep.fleet.vehicles[index].closest_clearance_m
        return value if math.isfinite(value) else None

    def close(self) -> None:
        self.lockstep.close()


class ExternalWorld:
    """Vehicles over MAVLink, one link each (``connects``), on the wall clock. Their closest
    approach is measured from their telemetry as it arrives (every sample of each against the
    latest of every other), in the fleet's frame."""

    announce = True
    runner_config = _RESENDS
    builtin = False

    def __init__(
        self, connects: Sequence[str], *, timeout_s: float, say: Callable[[str], None]
    ) -> None:
        self.transports: list[Transport] = []
        try:
            for url in connects:
                self.transports.append(open_transport(url, timeout_s=timeout_s, waiting=say))
        except BaseException:
            self.close()
            raise
        self.clock: Callable[[], float] = time.monotonic
        self.clock_ns: Callable[[], int] = time.time_ns
        self._closest = (math.inf, (0, 0))

    def true_pose(self, index: int) -> Callable[[], CameraPose] | None:  # noqa: ARG002
        return None  # photos come from where the telemetry says the camera is

    def run(self, runners: list[Runner]) -> list[Outcome]:
        for runner in runners:
            runner.begin()
        done = [False] * len(runners)
        poll_s = runners[0].config.poll_s / max(len(runners), 1)
        while not all(done):
            for i, runner in enumerate(runners):
                if not done[i] and runner.turn(poll_s):
                    done[i] = True
            self._measure(runners)
        return [r.finish() for r in runners]

    def _measure(self, runners: list[Runner]) -> None:
        """The closest two members came, by their latest telemetry (fleet frame)."""
        points = []
        for runner in runners:
            last = runner.mission.last
            flying = last is not None and not last.landed
            points.append((last.pos_enu_m if last is not None else None, flying))
        found = _pairwise_closest(points)
        if found is not None and found[0] < self._closest[0]:
            d, (i, j) = found
            sysids = (runners[i].link.target_system, runners[j].link.target_system)
            self._closest = (d, sysids)

    def approach(self) -> tuple[float, tuple[int, int]]:
        return self._closest

    def clearance(self, index: int, runner: Runner, scene: Scene) -> float | None:  # noqa: ARG002
        """Along the telemetry's route, as for one external vehicle."""
        route = [p for _, p in runner.route]
        value, _ = closest_clearance(
            route, scene, body_radius_m=body_radius_m(), offset_en=runner.scene_offset
        )
        return value if math.isfinite(value) else None

    def close(self) -> None:
        for transport in self.transports:
            transport.close()


def _pairwise_closest(
    points: list[tuple[tuple[float, float, float] | None, bool]],
) -> tuple[float, tuple[int, int]] | None:
    """The closest pair of known positions of which at least one is flying."""
    best: tuple[float, tuple[int, int]] | None = None
    for i, (a, a_flying) in enumerate(points):
        for j in range(i + 1, len(points)):
            b, b_flying = points[j]
            if a is None or b is None or not (a_flying or b_flying):
                continue
            d = math.dist(a, b)
            if best is None or d < best[0]:
                best = (d, (i, j))
    return best
