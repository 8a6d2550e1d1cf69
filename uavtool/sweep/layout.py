"""The sweep's output folder. Everything a flight leaves appears at once (written aside, then
renamed), so an interrupted sweep leaves only whole files::

    OUT/spec.toml                       the spec as run (overrides applied)
    OUT/plan.json                       every flight's file stem, in order: what --resume
                                        checks a spec against before it flies anything
    OUT/flights/000/000012-paper-1a2b3c4d.mcap   one recording per flight, 1000 per folder
    OUT/flights/000/000012-paper-1a2b3c4d.json   its result row
    OUT/results.parquet | results.csv   the table, one row per flight, in flight order
    OUT/summary.txt, OUT/summary.json, OUT/plots/*.png
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.recording.files import sync_folder
from uavtool.sweep.plan import FlightSpec

PER_FOLDER = 1000
_MCAP_MAGIC = b"\x89MCAP0\r\n"
_PART = ".part"
_PARTIAL = ".partial"  # where the recorder writes a recording until it is whole


@dataclass(frozen=True, slots=True)
class SweepLayout:
    root: Path

    @property
    def flights(self) -> Path:
        return self.root / "flights"

    def recording(self, flight: FlightSpec) -> Path:
        return self.flights / f"{flight.index // PER_FOLDER:03d}" / f"{flight.stem}.mcap"

    def row(self, flight: FlightSpec) -> Path:
        return self.recording(flight).with_suffix(".json")

    def table(self, extension: str) -> Path:
        return self.root / f"results.{extension}"

    @property
    def spec(self) -> Path:
        return self.root / "spec.toml"

    @property
    def plan(self) -> Path:
        return self.root / "plan.json"

    @property
    def summary(self) -> Path:
        return self.root / "summary.txt"

    @property
    def summary_json(self) -> Path:
        return self.root / "summary.json"

    @property
    def plots(self) -> Path:
        return self.root / "plots"

    def relative(self, path: Path) -> str:
        return path.relative_to(self.root).as_posix()

    def holds_sweep(self) -> bool:
        return self.flights.is_dir() and any(self.flights.glob("*/*.json"))

    def finished_row(self, flight: FlightSpec) -> dict[str, Any] | None:
        """The flight's row when its recording is whole (the size its row says, ending in the
        MCAP magic); None when the flight must be flown (again)."""
        try:
            row = json.loads(self.row(flight).read_text(encoding="utf-8"))
            path = self.recording(flight)
            with path.open("rb") as f:
                size = f.seek(0, os.SEEK_END)
                f.seek(max(size - len(_MCAP_MAGIC), 0))
                tail = f.read()
        except (OSError, ValueError):
            return None
        if not isinstance(row, dict) or row.get("recording_bytes") != size:
            return None
        return row if tail == _MCAP_MAGIC else None

    def remove_partials(self) -> int:
        """Delete what interrupted writers left (``*.part``, ``*.partial``); how many."""
        found = []
        if self.flights.is_dir():
            found = [*self.flights.glob(f"*/*{_PART}"), *self.flights.glob(f"*/*{_PARTIAL}")]
        for path in found:
            path.unlink(missing_ok=True)
        return len(found)


def part_path(path: Path) -> Path:
    """Where a writer puts ``path`` before renaming it into place (one per process)."""
    return path.with_name(f"{path.name}.{os.getpid()}{_PART}")


def write_atomic(path: Path, data: bytes) -> None:
    part = part_path(path)
    part.write_bytes(data)
    part.replace(path)
    sync_folder(path.parent)
