"""Read a ``.rrd`` back with Rerun's own reader, as rows per entity."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyarrow as pa
from rerun.chunk import RrdReader

_ROW_ID = "rerun.controls.RowId"


@dataclass
class Store:
    """Rows of every entity (path without the leading slash), ordered by vehicle time then
    logging order; a row is ``{column: value}`` with times as integer nanoseconds."""

    application_id: str
    rows: dict[str, list[dict[str, Any]]] = field(default_factory=lambda: defaultdict(list))
    timelines: dict[str, set[str]] = field(default_factory=lambda: defaultdict(set))
    static: set[str] = field(default_factory=set)

    def entities(self, prefix: str = "") -> set[str]:
        return {e for e in self.rows if e.startswith(prefix)}

    def last(self, entity: str) -> dict[str, Any]:
        return self.rows[entity][-1]

    def column(self, entity: str, name: str) -> list[Any]:
        return [row[name] for row in self.rows[entity] if name in row]


def _store(chunks: Any, application_id: str) -> Store:
    store = Store(application_id)
    for chunk in chunks:
        entity = chunk.entity_path.lstrip("/")
        batch = chunk.to_record_batch()
        timelines = set(chunk.timeline_names)
        store.timelines[entity] |= timelines
        if chunk.is_static:
            store.static.add(entity)
        columns: dict[str, list[Any]] = {}
        for name in batch.schema.names:
            col = batch.column(name)
            if name in timelines:
                col = col.cast(pa.int64())
            columns[name] = col.to_pylist()
        for i in range(batch.num_rows):
            store.rows[entity].append({name: values[i] for name, values in columns.items()})
    for rows in store.rows.values():
        rows.sort(key=lambda r: (r.get("vehicle_time") or 0, r[_ROW_ID]))
    return store


def read_rrd(path: Path) -> tuple[Store, Store]:
    """The recording and the blueprint stored in ``path`` (exactly one of each)."""
    reader = RrdReader(path)
    recordings, blueprints = reader.recordings(), reader.blueprints()
    assert len(recordings) == 1, recordings
    assert len(blueprints) == 1, blueprints
    rec = _store(reader.stream(store=recordings[0]), recordings[0].application_id)
    bp = _store(reader.stream(store=blueprints[0]), blueprints[0].application_id)
    return rec, bp


def views(blueprint: Store) -> list[tuple[str, str, str]]:
    """(class, name, origin) of each view in a blueprint."""
    out = []
    for entity in blueprint.entities("view/"):
        row = blueprint.last(entity)
        if "ViewBlueprint:class_identifier" in row:
            out.append(
                (
                    _one(row["ViewBlueprint:class_identifier"]),
                    _one(row.get("ViewBlueprint:display_name")),
                    _one(row.get("ViewBlueprint:space_origin")),
                )
            )
    return sorted(out)


def _one(value: Any) -> str:
    if isinstance(value, list):
        return str(value[0]) if value else ""
    return "" if value is None else str(value)
