"""The results table: one row per flight, in flight order, as Parquet or CSV (pyarrow).

Columns: the flight's index, key and scene; its inputs; then outcome (status, exit code,
reason, error), judgement (target and matched building, correct, scores and margin, model
built, IoU, tunnel kept, closest clearance and building), times (flight, vehicle, the vehicle
time limit, wall), route, photos, worker and recording. ``target_scores`` is a JSON list: the
target's score at each look. Only ``wall_s`` and ``worker`` depend on the run.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

RUN_DEPENDENT = ("wall_s", "worker")
"""Columns that differ between runs of the same spec; every other one is reproducible."""

_TYPES: dict[str, pa.DataType] = {
    "flight": pa.int64(),
    "key": pa.string(),
    "scene": pa.string(),
    "seed": pa.int64(),
    "wind_speed_ms": pa.float64(),
    "wind_from_deg": pa.float64(),
    "noise": pa.bool_(),
    "home_heading_deg": pa.float64(),
    "link_outages": pa.string(),
    "outage_start_s": pa.float64(),
    "outage_duration_s": pa.float64(),
    "vehicles": pa.int64(),
    "status": pa.string(),
    "exit_code": pa.int64(),
    "reason": pa.string(),
    "error": pa.string(),
    "target_building": pa.string(),
    "matched_building": pa.string(),
    "correct": pa.bool_(),
    "match_score": pa.float64(),
    "target_score": pa.float64(),
    "target_scores": pa.string(),
    "other_score": pa.float64(),
    "margin": pa.float64(),
    "model_built": pa.bool_(),
    "iou": pa.float64(),
    "tunnel_kept": pa.bool_(),
    "clearance_m": pa.float64(),
    "closest_building": pa.string(),
    "flight_time_s": pa.float64(),
    "vehicle_time_s": pa.float64(),
    "timeout_s": pa.float64(),
    "route_length_m": pa.float64(),
    "frames": pa.int64(),
    "closest_approach_m": pa.float64(),
    "separation_m": pa.float64(),
    "wall_s": pa.float64(),
    "worker": pa.string(),
    "recording": pa.string(),
    "recording_bytes": pa.int64(),
}
_NAMES = list(_TYPES)
OUTCOME_COLUMNS: tuple[str, ...] = tuple(_NAMES[_NAMES.index("status") :])


def columns(input_keys: Sequence[str]) -> tuple[str, ...]:
    return ("flight", "key", "scene", *input_keys, *OUTCOME_COLUMNS)


def to_table(rows: Sequence[dict[str, Any]], input_keys: Sequence[str]) -> pa.Table:
    """``rows`` sorted by flight, every column typed (missing values are nulls)."""
    ordered = sorted(rows, key=lambda r: int(r["flight"]))
    arrays, names = [], []
    for name in columns(input_keys):
        values = [r.get(name) for r in ordered]
        arrays.append(_array(name, values))
        names.append(name)
    return pa.Table.from_arrays(arrays, names=names)


def _array(name: str, values: list[Any]) -> pa.Array:
    kind = _TYPES.get(name)
    if kind is None:  # a set./param. column: its values' own type when they agree
        present = [v for v in values if v is not None]
        if present and all(isinstance(v, bool) for v in present):
            kind = pa.bool_()
        elif present and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in present
        ):
            kind = pa.float64()
        else:
            kind = pa.string()
            values = [v if v is None or isinstance(v, str) else json.dumps(v) for v in values]
    if kind == pa.float64():
        values = [None if v is None else float(v) for v in values]
    return pa.array(values, type=kind)


def write_table(table: pa.Table, path: Path) -> None:
    """Parquet, or CSV when ``path`` ends in ``.csv``; written aside, then renamed."""
    part = path.with_name(path.name + ".part")
    if path.suffix == ".csv":
        pa_csv.write_csv(table, part)
    else:
        pq.write_table(table, part)
    part.replace(path)


def read_table(path: Path) -> list[dict[str, Any]]:
    """Rows of a table written by :func:`write_table`."""
    table = pa_csv.read_csv(path) if path.suffix == ".csv" else pq.read_table(path)
    return list(table.to_pylist())
