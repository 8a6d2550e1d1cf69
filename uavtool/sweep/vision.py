"""``uavtool replay DIR --vision module:function``: a user's vision function over the photos
of many recordings, one Dask task each; each gets its detections written beside it, in the
output folder, and one table row."""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from uavtool.sweep.cluster import open_client
from uavtool.sweep.dispatch import run_tasks
from uavtool.sweep.progress import Progress, ProgressCallback
from uavtool.sweep.table import write_table
from uavtool.terminal import counted

_SCHEMA = pa.schema(
    [
        ("recording", pa.string()),
        ("written", pa.string()),
        ("photos", pa.int64()),
        ("detections", pa.int64()),
        ("error", pa.string()),
        ("worker", pa.string()),
        ("wall_s", pa.float64()),
    ]
)


def vision_recording(path: str, spec: str, out: str, code_dir: str) -> dict[str, Any]:
    """One row (a Dask task; errors are rows): ``spec`` over ``path``'s photos, written to
    ``out``. ``code_dir`` is where the client found the function's module (a worker process
    imports it from there too)."""
    from uavtool.replay.vision import load_function, run_vision  # noqa: PLC0415

    if code_dir not in sys.path:
        sys.path.insert(0, code_dir)
    wall0 = time.perf_counter()
    row: dict[str, Any] = {"recording": path}
    try:
        run = run_vision(Path(path), Path(out), spec, load_function(spec))
        row |= {"written": out, "photos": run.frames, "detections": run.detections}
    except Exception as exc:  # a recording that fails is a row
        row["error"] = f"{type(exc).__name__}: {exc}"
    try:
        from distributed import get_worker  # noqa: PLC0415

        row["worker"] = str(get_worker().name)
    except ValueError:
        row["worker"] = "in-process"
    return row | {"wall_s": time.perf_counter() - wall0}


@dataclass(frozen=True, slots=True)
class BatchVision:
    rows: tuple[dict[str, Any], ...]
    interrupted: bool


def vision_many(
    paths: Sequence[Path],
    *,
    spec: str,
    out_dir: Path,
    code_dir: str,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
) -> BatchVision:
    """Every recording as a Dask task; Ctrl-C returns the rows done (``interrupted``)."""
    report = progress or (lambda _p: None)
    names = _out_names(paths)
    rows: dict[int, dict[str, Any]] = {}
    interrupted = False
    try:
        with open_client(scheduler, workers=workers) as client:
            report(Progress(0, len(paths)))  # once connected: a refusal is its one line
            t0, errors = time.perf_counter(), 0
            items = [
                (str(p), spec, str(out_dir / n), code_dir)
                for p, n in zip(paths, names, strict=True)
            ]
            for task in run_tasks(client, vision_recording, items):
                row = task.result
                if task.error is not None:  # e.g. its worker died too often
                    row = {"recording": str(paths[task.index]), "error": str(task.error)}
                rows[task.index] = row
                errors += row.get("error") is not None
                report(Progress(len(rows), len(paths), 0, errors, time.perf_counter() - t0))
    except KeyboardInterrupt:
        interrupted = True
    return BatchVision(tuple(rows[i] for i in sorted(rows)), interrupted)


def _out_names(paths: Sequence[Path]) -> list[str]:
    """``<stem>.vision.mcap`` for each, numbered where two recordings share a stem."""
    seen: dict[str, int] = {}
    names = []
    for p in paths:
        n = seen[p.stem] = seen.get(p.stem, 0) + 1
        names.append(f"{p.stem}.vision.mcap" if n == 1 else f"{p.stem}-{n}.vision.mcap")
    return names


def write_vision_table(batch: BatchVision, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_table(pa.Table.from_pylist(list(batch.rows), schema=_SCHEMA), path)


def format_vision_summary(batch: BatchVision, *, total: int, spec: str, table: Path) -> str:
    n = len(batch.rows)
    done = [r for r in batch.rows if r.get("error") is None]
    lines = [
        f"recordings     {n} of {total}" + ("" if n == total else " (interrupted)"),
        f"vision         {spec}: {counted(sum(r['detections'] for r in done), 'detection')} "
        f"on {counted(sum(r['photos'] for r in done), 'photo')}",
        f"written        {len(done)} recordings with detections; table {table}",
    ]
    lines += [
        f"error          {r['recording']}: {r['error']}" for r in batch.rows if r.get("error")
    ]
    return "\n".join(lines)
