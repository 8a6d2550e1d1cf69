"""One flight as a Dask task: fly it in lockstep on the built-in vehicle, judge it against the
scene, and leave its recording and result row in the sweep's folder (each renamed into place
whole). A flight that raises is a row with its error; only trouble outside the flight (a full
disk) escapes, for Dask to retry.

A flight may be given a timeout in *vehicle* seconds, not wall seconds: in lockstep a flight
that never ends still moves the vehicle's clock (every wait for the vehicle advances it), so it
is stopped at the same point on any machine and under any load, and the table stays the same
for the same spec. A wall-clock limit would stop different flights on a busy machine."""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from uavtool.errors import UavtoolError
from uavtool.recording.files import sync_folder
from uavtool.sweep.errors import FlightTimeoutError
from uavtool.sweep.layout import SweepLayout, part_path, write_atomic
from uavtool.sweep.plan import FlightSpec
from uavtool.sweep.scenes import load_source_scene

if TYPE_CHECKING:
    from uavtool.mission import Outcome, Telemetry
    from uavtool.runner.evaluate import Evaluation
    from uavtool.runner.fly import FlyConfig

ERROR = "error"
"""The status of a flight that raised."""


def run_flight(
    flight: FlightSpec,
    root: str,
    *,
    input_keys: tuple[str, ...],
    exit_codes: Mapping[str, int],
    timeout_s: float | None = None,
) -> dict[str, Any]:
    """Fly ``flight`` into the sweep folder ``root``, stopped after ``timeout_s`` vehicle
    seconds; its result row (JSON types only)."""
    layout = SweepLayout(Path(root))
    recording = layout.recording(flight)
    recording.parent.mkdir(parents=True, exist_ok=True)
    part = part_path(recording)
    wall0 = time.perf_counter()
    row = input_row(flight, input_keys) | {"timeout_s": timeout_s}
    try:
        row.update(_fly(flight, part, row, exit_codes, timeout_s))
    except Exception as exc:  # a flight that raises is a row, not a lost sweep
        row.update(error_columns(exc))
    row["wall_s"] = time.perf_counter() - wall0
    row["worker"] = _worker_name()
    if part.exists():
        row["recording"] = layout.relative(recording)
        row["recording_bytes"] = part.stat().st_size
    # The row first: a recording in place always has its row (resume trusts the pair).
    write_atomic(layout.row(flight), json.dumps(row, sort_keys=True).encode())
    if part.exists():
        part.replace(recording)
        sync_folder(recording.parent)
    return row


def input_row(flight: FlightSpec, input_keys: tuple[str, ...]) -> dict[str, Any]:
    row: dict[str, Any] = {"flight": flight.index, "key": flight.key, "scene": flight.label}
    for key in input_keys:
        value = flight.value(key)
        row[key] = json.dumps(value) if isinstance(value, (list, tuple)) else value
    return row | {"recording": None, "recording_bytes": None}


def error_columns(exc: BaseException) -> dict[str, Any]:
    code = exc.exit_code if isinstance(exc, UavtoolError) else 1
    return {"status": ERROR, "exit_code": code, "error": f"{type(exc).__name__}: {exc}"}


def _fly(
    flight: FlightSpec,
    record: Path,
    row: dict[str, Any],
    exit_codes: Mapping[str, int],
    timeout_s: float | None,
) -> dict[str, Any]:
    from uavtool.mission import SearchMission  # noqa: PLC0415
    from uavtool.mission.params import with_overrides  # noqa: PLC0415
    from uavtool.plugins import resolve  # noqa: PLC0415
    from uavtool.runner.fly import FlyConfig, fly  # noqa: PLC0415
    from uavtool.sweep.scores import recognition_scores  # noqa: PLC0415

    scene = load_source_scene(flight.scene, flight.scene_seed)
    heading = flight.value("home_heading_deg")
    if heading is not None:
        scene = dataclasses.replace(scene, home_heading_deg=float(heading))
    row["home_heading_deg"] = scene.home_heading_deg
    mission = resolve(flight.mission)[0]
    config = FlyConfig(
        scene=scene,
        record=record,
        record_in_process=True,  # every core flies: a writer process would only add work
        mission=flight.mission,
        params=with_overrides(mission.params_type(), flight.settings()),
        vehicle_params=flight.vehicle_params(),
        seed=int(flight.value("seed")),
        noise=bool(flight.value("noise")),
        wind=(float(flight.value("wind_speed_ms")), float(flight.value("wind_from_deg"))),
        link_outages_s=flight.link_outages_s(),
    )
    vehicles = int(flight.value("vehicles"))
    if vehicles > 1:
        searched = issubclass(mission, SearchMission)
        fleet = dataclasses.replace(config, vehicles=vehicles)
        return _fly_fleet(fleet, exit_codes, timeout_s, searched=searched)
    s = fly(config, progress=None if timeout_s is None else VehicleDeadline(timeout_s))
    o, e = s.outcome, s.evaluation
    columns: dict[str, Any] = {
        "status": o.status.value,
        "exit_code": exit_codes.get(o.status.value),
        "reason": o.reason,
        "error": None,
        "clearance_m": s.clearance_m,
        "closest_building": s.clearance_building or None,
        "flight_time_s": s.flight_time_s,
        "vehicle_time_s": s.vehicle_time_s,
        "route_length_m": s.route_length_m,
        "frames": s.frames,
    }
    if not s.searched:  # another mission: its outcome, not the search's findings
        return columns
    scores = recognition_scores(record, scene)
    return (
        columns
        | _match_columns(e, o)
        | {
            "target_scores": json.dumps(scores.target_looks),
            "target_score": scores.target,
            "other_score": scores.other,
            "margin": scores.margin,
            "tunnel_kept": e.tunnel_kept,
        }
    )


def _match_columns(e: Evaluation, o: Outcome) -> dict[str, Any]:
    """What the search found, judged against the scene (one vehicle's, or a fleet's first)."""
    return {
        "target_building": e.target_building,
        "matched_building": e.matched_building or None,
        "correct": bool(e.matched_building) and e.matched_building == e.target_building,
        "match_score": o.match_score if o.matched_poi >= 0 else None,
        "model_built": o.model_built,
        "iou": e.model_iou,
    }


def _fly_fleet(
    config: FlyConfig, exit_codes: Mapping[str, int], timeout_s: float | None, *, searched: bool
) -> dict[str, Any]:
    """A fleet's flight (homes on the first offset line clear of the buildings): the fleet's
    outcome, and its first vehicle's match judged as one vehicle's is."""
    from uavtool.runner.fleet import fly_fleet  # noqa: PLC0415

    deadline = None if timeout_s is None else VehicleDeadline(timeout_s)
    s = fly_fleet(
        dataclasses.replace(config, offset_line=None),
        progress=None if deadline is None else lambda _v, text, t: deadline(text, t),
    )
    clearances = [v.clearance_m for v in s.vehicles if v.clearance_m is not None]
    columns: dict[str, Any] = {
        "status": s.status.value,
        "exit_code": exit_codes.get(s.status.value),
        "reason": s.reason,
        "error": None,
        "clearance_m": min(clearances) if clearances else None,
        "flight_time_s": s.vehicle_time_s,
        "vehicle_time_s": s.vehicle_time_s,
        "route_length_m": sum(v.route_length_m for v in s.vehicles),
        "frames": sum(v.frames for v in s.vehicles),
        "closest_approach_m": s.closest_approach_m if s.closest_approach_m < 1e9 else None,
        "separation_m": s.separation_m,
    }
    e = s.evaluation
    if e is None or not searched:
        return columns
    return columns | _match_columns(e, s.vehicles[0].outcome)


class VehicleDeadline:
    """A ``fly`` progress hook that stops the flight (FlightTimeoutError) at the first mission
    event after the vehicle's clock passed ``timeout_s`` (the built-in vehicle boots as the
    flight starts)."""

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = timeout_s

    def __call__(self, _event: str, telemetry: Telemetry | None) -> None:
        if telemetry is not None and telemetry.time_boot_ms > 1000.0 * self.timeout_s:
            raise FlightTimeoutError(self.timeout_s)


def _worker_name() -> str:
    try:
        from distributed import get_worker  # noqa: PLC0415

        return str(get_worker().name)
    except (ImportError, ValueError):
        return "in-process"
