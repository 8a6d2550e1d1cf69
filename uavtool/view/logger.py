"""`MissionLogger`: turns a mission's observations and outputs into Rerun entities.

It takes the same JSON dictionaries the recording holds on ``/mission/observations`` and
``/mission/outputs``, so `uavtool view` (reading a recording) and `uavtool fly --rerun`
(logging while flying) go through this one class. Outputs carry no vehicle time: they are
logged at the time of the latest observation, the one that produced them.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import rerun as rr

from uavtool.camera import CameraPose, Intrinsics
from uavtool.geo import GeoPoint
from uavtool.view import entities as ent
from uavtool.view.findings import Findings
from uavtool.view.paths import FleetVehicle, Paths
from uavtool.view.telemetry import Sample, TelemetryLog, log_series_styles, set_times
from uavtool.world import Scene

_EVENT_LEVELS = {"info": "INFO", "warning": "WARN", "error": "ERROR"}
_POI_ABOVE_M = 2.0  # points of interest float this far above the tallest building


@dataclass(frozen=True, slots=True)
class LogCounts:
    """What a logger has logged so far."""

    frames: int
    shapes: int
    telemetry: int
    route_points: int
    pois: int
    recognitions: int
    models: int
    texts: int
    pictures: int = 0
    detections: int = 0


def statustext_level(severity: int) -> str:
    """Rerun's text-log level for a MAVLink ``MAV_SEVERITY`` (0 emergency … 7 debug)."""
    if severity <= 2:
        return "CRITICAL"
    return {3: "ERROR", 4: "WARN", 5: "INFO", 6: "INFO"}.get(severity, "DEBUG")


def poi_height_m(scene: Scene) -> float:
    """The height points of interest are drawn at: over the tallest building of ``scene``."""
    tops = [blk.top_m for b in scene.buildings for blk in b.blocks]
    return max(tops, default=8.0) + _POI_ABOVE_M


class MissionLogger:
    """Logs one mission into ``rec`` under ``prefix``; ``batch`` telemetry samples per send
    (small when live, so the viewer keeps up; large when converting a file).

    With ``vehicle``, the mission of one vehicle of a fleet: its entities under its name
    (``world/uav2/…``, in its own frame, placed at its home), the fleet's world and target
    logged by a `~uavtool.view.fleet.FleetLogger`."""

    def __init__(
        self,
        rec: rr.RecordingStream,
        *,
        prefix: str = "",
        batch: int = 10,
        vehicle: FleetVehicle | None = None,
    ) -> None:
        self.rec = rec
        self.paths = Paths(prefix, vehicle.name if vehicle is not None else "")
        self.batch = batch
        self.vehicle = vehicle
        colour = ent.vehicle_rgb(vehicle.sysid) if vehicle is not None else None
        self.telemetry = TelemetryLog(rec, self.paths, route_rgb=colour)
        self.findings = Findings(
            rec, self.paths, home_en_m=vehicle.home_en_m if vehicle is not None else None
        )
        self._vehicle_ns: int | None = None
        self._photo_pos: list[tuple[float, float, float]] = []
        self._photo_tags: list[str] = []
        self._mode: tuple[str, bool] | None = None
        self._texts = 0
        self._pictures = 0
        self._detections = 0
        if vehicle is None:
            ent.log_world(rec, self.paths)
            log_series_styles(rec, self.paths)
        else:
            rgb = ent.vehicle_rgb(vehicle.sysid)
            ent.log_fleet_vehicle(rec, self.paths, home_en_m=vehicle.home_en_m, rgb=rgb)
            log_series_styles(rec, self.paths, shade=vehicle.sysid - 1)

    # --- set-up --------------------------------------------------------------------------------

    def scene(self, scene: Scene) -> None:
        """The ground truth: buildings (static meshes) and the height to draw POIs at."""
        ent.log_scene(self.rec, self.paths, scene=scene)
        self.findings.poi_height_m = poi_height_m(scene)

    def home(self, home: GeoPoint) -> None:
        """The vehicle's home: from now on positions also go on the map."""
        self.telemetry.home = home

    def params(self, params: Mapping[str, Any]) -> None:
        """The mission parameters (as recorded): the recognition threshold is plotted."""
        value = params.get("recognize", {}).get("threshold")
        self.findings.threshold = float(value) if isinstance(value, int | float) else None

    def target(self, png: bytes) -> None:
        ent.log_target(self.rec, self.paths, png=png)

    # --- the mission's stream --------------------------------------------------------------------

    def observation(
        self,
        step: int,
        obs: Mapping[str, Any],
        image_png: bytes | None = None,
        *,
        log_time_ns: int | None = None,
    ) -> None:
        """One observation as recorded (``Telemetry``, ``Photo`` with its PNG, …)."""
        del step  # kept in the signature: the same call as the recorder's
        ms = obs.get("time_boot_ms")
        if isinstance(ms, int) and ms > 0:
            self._vehicle_ns = ms * 1_000_000
        kind = obs.get("type")
        if kind == "Telemetry":
            self._telemetry(obs, log_time_ns)
            return
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        if kind == "Photo":
            self._photo(obs, image_png)
        elif kind == "CommandResult" and not obs.get("accepted", True):
            self._text(
                "commands", f"action {obs.get('action_id')}: {obs.get('detail', 'refused')}", "WARN"
            )
        elif kind == "LinkLost":
            self._text("runner", "link lost", "WARN")
        elif kind == "LinkRestored":
            self._text("runner", "link restored", "INFO")

    def output(self, n: int, out: Mapping[str, Any], *, log_time_ns: int | None = None) -> None:
        """One output as recorded (commands, ``Event``, ``Shapes``, ``Plan`` …)."""
        del n
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        kind = str(out.get("type"))
        handler = _OUTPUT_HANDLERS.get(kind)
        if handler is not None:
            handler(self, out)
        else:  # a command to the vehicle (GoTo, TakePhoto …): one line each
            self._text("commands", _command_text(out), "DEBUG")

    def picture(self, tag: str, png: bytes, *, log_time_ns: int | None = None) -> None:
        """An image the mission made (its PNG, from ``/mission/pictures``)."""
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        ent.log_picture(self.rec, self.paths, tag=tag, png=png)
        self._pictures += 1

    def detections(self, payload: Mapping[str, Any], *, log_time_ns: int | None = None) -> None:
        """A vision function's detections on one frame (``/vision/detections``)."""
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        found = payload.get("detections")
        if isinstance(found, list):
            items = [d for d in found if isinstance(d, Mapping)]
            self._detections += ent.log_detections(self.rec, self.paths, detections=items)

    def statustext(self, severity: int, text: str, *, log_time_ns: int | None = None) -> None:
        """A MAVLink STATUSTEXT from the vehicle."""
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        self._text("vehicle", text, statustext_level(severity))

    def note(
        self, level: str, text: str, *, source: str = "runner", log_time_ns: int | None = None
    ) -> None:
        """A line from the runner (``level`` info/warning/error)."""
        set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
        self._text(source, text, _EVENT_LEVELS.get(level, "INFO"))

    def flush(self) -> None:
        """Send buffered telemetry."""
        self.telemetry.flush()

    @property
    def vehicle_ns(self) -> int | None:
        """The vehicle time of the latest observation (None before the first)."""
        return self._vehicle_ns

    @property
    def counts(self) -> LogCounts:
        f = self.findings
        return LogCounts(
            frames=len(self._photo_tags),
            shapes=f.shape_count,
            telemetry=self.telemetry.samples,
            route_points=self.telemetry.route_points,
            pois=len(f.pois),
            recognitions=f.recognitions,
            models=f.models,
            texts=self._texts,
            pictures=self._pictures,
            detections=self._detections,
        )

    # --- observations ----------------------------------------------------------------------------

    def _telemetry(self, obs: Mapping[str, Any], log_time_ns: int | None) -> None:
        if self._vehicle_ns is None:
            return  # no vehicle time yet: nothing to put it on
        self.telemetry.add(
            Sample(
                vehicle_ns=self._vehicle_ns,
                log_ns=log_time_ns,
                pos_enu_m=_vec3(obs.get("pos_enu_m")),
                vel_enu_m_s=_vec3(obs.get("vel_enu_m_s")),
                heading_deg=float(obs.get("heading_deg") or 0.0),
                gimbal_pitch_deg=float(obs.get("gimbal_pitch_deg") or 0.0),
                battery_pct=float(obs.get("battery_pct") or 0.0),
            )
        )
        mode = (str(obs.get("mode")), bool(obs.get("armed")))
        if mode != self._mode:
            set_times(self.rec, vehicle_ns=self._vehicle_ns, log_ns=log_time_ns)
            self._text("vehicle", f"mode {mode[0]}, {'armed' if mode[1] else 'disarmed'}", "INFO")
            self._mode = mode
        if self.telemetry.pending >= self.batch:
            self.telemetry.flush()

    def _photo(self, obs: Mapping[str, Any], png: bytes | None) -> None:
        pose_d, intr_d = obs.get("pose") or {}, obs.get("intrinsics") or {}
        pose = CameraPose(
            _vec3(pose_d.get("pos_enu_m")), float(pose_d["heading_deg"]), float(pose_d["pitch_deg"])
        )
        intrinsics = Intrinsics(
            int(intr_d["width_px"]),
            int(intr_d["height_px"]),
            float(intr_d["fx_px"]),
            float(intr_d["fy_px"]),
            float(intr_d["cx_px"]),
            float(intr_d["cy_px"]),
        )
        ent.log_photo(self.rec, self.paths, pose=pose, intrinsics=intrinsics, png=png)
        self.findings.frame = int(obs.get("frame_index", len(self._photo_tags)))
        self._photo_pos.append(pose.pos_enu_m)
        self._photo_tags.append(str(obs.get("tag", "")))
        ent.log_photo_positions(
            self.rec, self.paths, positions_enu_m=self._photo_pos, tags=self._photo_tags
        )

    # --- outputs ---------------------------------------------------------------------------------

    def _event(self, out: Mapping[str, Any]) -> None:
        level = _EVENT_LEVELS.get(str(out.get("level")), "INFO")
        self._text("mission", str(out.get("text", "")), level)

    def _viewpoints(self, out: Mapping[str, Any]) -> None:
        for problem in self.findings.viewpoints(out):
            self._text("mission", problem, "WARN")

    def _outcome(self, out: Mapping[str, Any]) -> None:
        level = {"completed": "INFO", "partial": "WARN", "no-match": "WARN"}.get(
            str(out.get("status")), "ERROR"
        )
        self._text("mission", f"outcome: {out.get('status')}: {out.get('reason')}", level)

    # --- helpers ---------------------------------------------------------------------------------

    def _text(self, source: str, text: str, level: str) -> None:
        ent.log_text(self.rec, self.paths.log_source(source), text=text, level=level)
        self._texts += 1


_OUTPUT_HANDLERS: dict[str, Callable[[MissionLogger, Mapping[str, Any]], None]] = {
    "Event": MissionLogger._event,
    "Shapes": lambda self, out: self.findings.shapes(out),
    "Plan": lambda self, out: self.findings.plan(out),
    "Recognition": lambda self, out: self.findings.recognition(out),
    "Viewpoints": MissionLogger._viewpoints,
    "DiagonalView": lambda self, out: self.findings.diagonal(out),
    "ModelBuilt": lambda self, out: self.findings.model(out),
    "Outcome": MissionLogger._outcome,
    "Result": lambda self, out: self._text(
        "mission", f"result {out.get('tag')}: {json.dumps(out.get('values'))[:500]}", "INFO"
    ),
    "Picture": lambda _self, _out: None,  # its image comes from /mission/pictures
}


def _vec3(value: object) -> tuple[float, float, float]:
    if isinstance(value, Sequence) and len(value) >= 3:
        return (float(value[0]), float(value[1]), float(value[2]))
    return (0.0, 0.0, 0.0)


def _command_text(out: Mapping[str, Any]) -> str:
    fields = ", ".join(f"{k}={v}" for k, v in out.items() if k not in ("type", "n", "step"))
    return f"{out.get('type')} {fields}"
