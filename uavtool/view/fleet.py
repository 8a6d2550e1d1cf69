"""`FleetLogger`: a fleet's flight in Rerun, every vehicle beside the others in one world.

The fleet's world is ENU metres around vehicle 1's home, as the fleet mission's; the scene,
the axes and the target picture are logged once, for all. Each vehicle is one `MissionLogger`
whose entities go under its name — ``world/uav2/route``, ``world/uav2/vehicle``,
``world/uav2/camera/image``, ``plots/uav2/…``, ``log/uav2/…``, ``map/uav2/vehicle`` — in
its own frame (its telemetry's: ENU around its own home), that frame placed at its home in
the fleet's, so every route is drawn where it was flown. The fleet's own lines (its outcome)
go to ``log/fleet``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import rerun as rr

from uavtool.view import entities as ent
from uavtool.view.logger import LogCounts, MissionLogger, poi_height_m
from uavtool.view.paths import FleetVehicle, Paths
from uavtool.view.telemetry import set_times
from uavtool.world import Scene

_LEVELS = {"info": "INFO", "warning": "WARN", "error": "ERROR"}


class FleetLogger:
    """Logs a fleet's flight into ``rec``: the shared world once, and each of ``vehicles``
    through its own `MissionLogger` (``vehicles[sysid]``); ``batch`` as for one."""

    def __init__(
        self, rec: rr.RecordingStream, vehicles: Sequence[FleetVehicle], *, batch: int = 10
    ) -> None:
        self.rec = rec
        self.paths = Paths()
        self.vehicles = {v.sysid: MissionLogger(rec, batch=batch, vehicle=v) for v in vehicles}
        self._texts = 0
        ent.log_axes(rec, self.paths)

    def scene(self, scene: Scene) -> None:
        """The ground truth, once for the fleet (at the fleet frame's origin)."""
        ent.log_scene(self.rec, self.paths, scene=scene)
        for logger in self.vehicles.values():
            logger.findings.poi_height_m = poi_height_m(scene)

    def params(self, params: Mapping[str, Any]) -> None:
        """The mission parameters, one set for every member."""
        for logger in self.vehicles.values():
            logger.params(params)

    def target(self, png: bytes) -> None:
        """The target picture, the fleet's (every member's shapes of it drawn over it)."""
        ent.log_target(self.rec, self.paths, png=png)

    def note(self, level: str, text: str, *, log_time_ns: int | None = None) -> None:
        """A line of the fleet's (``level`` info/warning/error), at the latest vehicle time
        any vehicle has reached."""
        times = [t for t in (v.vehicle_ns for v in self.vehicles.values()) if t is not None]
        set_times(self.rec, vehicle_ns=max(times, default=None), log_ns=log_time_ns)
        ent.log_text(
            self.rec, self.paths.log_source("fleet"), text=text, level=_LEVELS.get(level, "INFO")
        )
        self._texts += 1

    def flush(self) -> None:
        """Send every vehicle's buffered telemetry."""
        for logger in self.vehicles.values():
            logger.flush()

    @property
    def vehicle_counts(self) -> dict[int, LogCounts]:
        """What was logged for each vehicle, by system id."""
        return {sysid: logger.counts for sysid, logger in self.vehicles.items()}

    @property
    def counts(self) -> LogCounts:
        """What was logged for the whole fleet: the vehicles' counts added up."""
        names = [f.name for f in dataclasses.fields(LogCounts)]
        every = list(self.vehicle_counts.values())
        total = {n: sum(getattr(c, n) for c in every) for n in names}
        total["texts"] += self._texts
        return LogCounts(**total)
