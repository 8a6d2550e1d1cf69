"""Batch replay (``uavtool replay DIR_OR_GLOB``): many recordings through the mission on the
same Dask set-up as a sweep, one row per recording, and how many decide differently.

Each row says whether the replayed outputs are identical to the recorded ones, where they
first differ, or at which step the mission's decisions left the recording and why; and the
decision (which point of interest matched) before and after. When the mission diverged
before it ended, the decision after is the per-frame one: the first photographed point of
interest the re-analysed vision matches.

A recording of ``uavtool record`` has no mission to replay: under ``--vision-only`` each of
its photos is vectorized and judged against ``--target`` (:mod:`uavtool.replay.photos`, as
for one such file) and its row counts the photos and names the frames that match.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from uavtool.errors import InputError
from uavtool.sweep.cluster import open_client
from uavtool.sweep.dispatch import run_tasks
from uavtool.sweep.progress import Progress, ProgressCallback
from uavtool.sweep.table import write_table
from uavtool.terminal import counted

IDENTICAL, DIFFERS, DIVERGED, VISION_ONLY, ERROR = (
    "identical",
    "differs",
    "diverged",
    "vision-only",
    "error",
)

_SCHEMA = pa.schema(
    [
        ("recording", pa.string()),
        ("result", pa.string()),
        ("steps", pa.int64()),
        ("outputs_recorded", pa.int64()),
        ("outputs_replayed", pa.int64()),
        ("first_difference_step", pa.int64()),
        ("first_difference", pa.string()),
        ("diverged_step", pa.int64()),
        ("diverged_reason", pa.string()),
        ("status_before", pa.string()),
        ("status_after", pa.string()),
        ("matched_poi_before", pa.int64()),
        ("matched_poi_after", pa.int64()),
        ("decision_after_from", pa.string()),
        ("decision_changed", pa.bool_()),
        ("frames_changed", pa.int64()),
        ("photos", pa.int64()),
        ("photos_matched", pa.int64()),
        ("matched_frames", pa.string()),
        ("error", pa.string()),
        ("wall_s", pa.float64()),
        ("worker", pa.string()),
    ]
)


def find_recordings(pattern: str) -> list[Path]:
    """A folder's ``.mcap`` files (and its sub-folders'), or a glob's matches (``**`` too),
    sorted; InputError when there are none."""
    path = Path(pattern)
    if path.is_dir():
        found = sorted(path.rglob("*.mcap"))
    else:
        parts = path.parts
        first = next((i for i, part in enumerate(parts) if set("*?[") & set(part)), len(parts))
        base = Path(*parts[:first]) if first else Path()
        rest = "/".join(parts[first:])
        found = sorted(p for p in base.glob(rest) if p.suffix == ".mcap") if rest else []
    if not found:
        raise InputError(f"{pattern}: no .mcap recordings there")
    return found


def replay_recording(
    path: str, overrides: Mapping[str, Any], vision_only: bool, target_png: bytes | None = None
) -> dict[str, Any]:
    """One row: the recording replayed with ``overrides`` (a Dask task; errors are rows).
    ``target_png``: the picture a recording of ``uavtool record`` is matched against."""
    from uavtool.replay.load import is_fleet  # noqa: PLC0415
    from uavtool.replay.photos import is_recorded_flight  # noqa: PLC0415

    wall0 = time.perf_counter()
    row: dict[str, Any] = {"recording": path}
    try:
        if vision_only and is_recorded_flight(path):
            row |= _photos(Path(path), overrides, target_png)
        elif is_fleet(path):
            row |= _replay_fleet(Path(path), overrides, vision_only)
        else:
            row |= _replay(Path(path), overrides, vision_only)
    except Exception as exc:  # a recording that fails is a row
        row |= {"result": ERROR, "error": f"{type(exc).__name__}: {exc}"}
    try:
        from distributed import get_worker  # noqa: PLC0415

        row["worker"] = str(get_worker().name)
    except ValueError:
        row["worker"] = "in-process"
    return row | {"wall_s": time.perf_counter() - wall0}


def _replay(path: Path, overrides: Mapping[str, Any], vision_only: bool) -> dict[str, Any]:
    from uavtool.mission.params import with_overrides  # noqa: PLC0415
    from uavtool.replay import load_flight, reanalyse_frames, replay  # noqa: PLC0415

    flight = load_flight(path)
    if flight.truncated:
        raise InputError(f"{path}: the recording is truncated; replay needs a whole file")
    params = with_overrides(flight.params, dict(overrides))
    before = _outcome([o.data for o in flight.outputs])
    frames = reanalyse_frames(flight, params)
    matched = [p for c in frames if c.matched_after and (p := _poi(c.tag)) is not None]
    per_frame = matched[0] if matched else -1
    row: dict[str, Any] = {
        "outputs_recorded": len(flight.outputs),
        "status_before": before[0],
        "matched_poi_before": before[1],
        "frames_changed": sum(c.changed for c in frames),
    }
    if vision_only:
        after: tuple[str | None, int] = (None, per_frame)
        row |= {"result": VISION_ONLY, "decision_after_from": "frames"}
    else:
        result = replay(flight, params)
        after = _outcome([o.data for o in result.outputs]) if result.finished else (None, per_frame)
        d, fd = result.divergence, result.first_difference
        row |= {
            "result": IDENTICAL if result.identical else DIVERGED if d else DIFFERS,
            "steps": result.steps,
            "outputs_replayed": len(result.outputs),
            "first_difference_step": fd.step if fd else None,
            "first_difference": fd.describe() if fd else None,
            "diverged_step": d.step if d else None,
            "diverged_reason": d.reason if d else None,
            "decision_after_from": "mission" if result.finished else "frames",
        }
    return row | {
        "status_after": after[0],
        "matched_poi_after": after[1],
        "decision_changed": after[1] != before[1],
    }


def _replay_fleet(path: Path, overrides: Mapping[str, Any], vision_only: bool) -> dict[str, Any]:
    """A fleet's row: every member replayed (:func:`uavtool.replay.fleet.replay_fleet`); the
    first vehicle that differs or diverges names the row's difference (``uavK: …``), and the
    decision is the fleet's, its first vehicle's (the leader of ``fleet-search``)."""
    from uavtool.mission.params import with_overrides  # noqa: PLC0415
    from uavtool.replay.fleet import replay_fleet  # noqa: PLC0415
    from uavtool.replay.load import load_fleet  # noqa: PLC0415

    if vision_only:
        raise InputError(f"{path}: a fleet's recording: --vision-only takes one vehicle's")
    fleet = load_fleet(path)
    if fleet.truncated:
        raise InputError(f"{path}: the recording is truncated; replay needs a whole file")
    results = replay_fleet(fleet, with_overrides(fleet.params, dict(overrides)))
    named = [(f"uav{v.sysid}: ", r) for v, r in zip(fleet.vehicles, results, strict=True)]
    diverged = next(((who, r.divergence) for who, r in named if r.divergence), None)
    differs = next(((who, r.first_difference) for who, r in named if r.first_difference), None)
    leader = results[0]
    before = _outcome([o.data for o in fleet.vehicles[0].outputs])
    after = _outcome([o.data for o in leader.outputs]) if leader.finished else (None, -1)
    return {
        "result": IDENTICAL
        if all(r.identical for r in results)
        else DIVERGED
        if diverged
        else DIFFERS,
        "steps": sum(r.steps for r in results),
        "outputs_recorded": sum(len(v.outputs) for v in fleet.vehicles),
        "outputs_replayed": sum(len(r.outputs) for r in results),
        "first_difference_step": differs[1].step if differs else None,
        "first_difference": differs[0] + differs[1].describe() if differs else None,
        "diverged_step": diverged[1].step if diverged else None,
        "diverged_reason": diverged[0] + diverged[1].reason if diverged else None,
        "decision_after_from": "mission" if leader.finished else None,
        "status_before": before[0],
        "matched_poi_before": before[1],
        "status_after": after[0],
        "matched_poi_after": after[1],
        "decision_changed": after[1] != before[1],
    }


def _photos(path: Path, overrides: Mapping[str, Any], target_png: bytes | None) -> dict[str, Any]:
    from uavtool.mission import Params  # noqa: PLC0415
    from uavtool.mission.params import with_overrides  # noqa: PLC0415
    from uavtool.replay.photos import analyse_photos  # noqa: PLC0415

    if target_png is None:
        raise InputError(
            "a recording of `uavtool record` has no mission and no target picture: "
            "give one with --target PNG"
        )
    analysis = analyse_photos(path, target_png, with_overrides(Params(), dict(overrides)))
    matched = analysis.matches
    return {
        "result": VISION_ONLY,
        "decision_after_from": "all frames" if analysis.all_frames else "photos",
        "photos": len(analysis.results),
        "photos_matched": len(matched),
        "matched_frames": ",".join(str(r.frame_index) for r in matched),
    }


def _outcome(outputs: Sequence[Mapping[str, Any]]) -> tuple[str | None, int]:
    for data in reversed(outputs):
        if data.get("type") == "Outcome":
            return str(data.get("status")), int(data.get("matched_poi", -1))
    return None, -1


def _poi(tag: str) -> int | None:
    parts = tag.split("-")
    return int(parts[1]) if parts[0] == "poi" and len(parts) > 1 and parts[1].isdigit() else None


@dataclass(frozen=True, slots=True)
class BatchReplay:
    rows: tuple[dict[str, Any], ...]
    """In the order of the recordings."""
    interrupted: bool

    def count(self, result: str) -> int:
        return sum(r.get("result") == result for r in self.rows)

    @property
    def decisions_changed(self) -> tuple[str, ...]:
        return tuple(r["recording"] for r in self.rows if r.get("decision_changed"))


def replay_many(
    paths: Sequence[Path],
    *,
    overrides: Mapping[str, Any],
    vision_only: bool = False,
    target_png: bytes | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: ProgressCallback | None = None,
) -> BatchReplay:
    """Replay every recording as a Dask task; Ctrl-C returns the rows done (``interrupted``).
    ``target_png``: what the photos of ``uavtool record``'s recordings are matched against."""
    report = progress or (lambda _p: None)
    rows: dict[int, dict[str, Any]] = {}
    interrupted = False
    try:
        with open_client(scheduler, workers=workers) as client:
            report(Progress(0, len(paths)))  # once connected: a refusal is its one line
            t0 = time.perf_counter()
            errors = 0
            for task in run_tasks(
                client,
                replay_recording,
                [(str(p),) for p in paths],
                kwargs={
                    "overrides": dict(overrides),
                    "vision_only": vision_only,
                    "target_png": target_png,
                },
            ):
                row = task.result
                if task.error is not None:  # e.g. its worker died too often
                    row = {"recording": str(paths[task.index]), "result": ERROR}
                    row["error"] = str(task.error)
                rows[task.index] = row
                errors += row["result"] == ERROR
                report(Progress(len(rows), len(paths), 0, errors, time.perf_counter() - t0))
    except KeyboardInterrupt:
        interrupted = True
    return BatchReplay(tuple(rows[i] for i in sorted(rows)), interrupted)


def write_replay_table(batch: BatchReplay, path: Path) -> None:
    """Parquet, or CSV when ``path`` ends in ``.csv``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_table(pa.Table.from_pylist(list(batch.rows), schema=_SCHEMA), path)


def format_replay_summary(batch: BatchReplay, *, total: int, changed_params: bool) -> str:
    n = len(batch.rows)
    lines = [f"recordings     {n} of {total}" + ("" if n == total else " (interrupted)")]
    counts = [(k, batch.count(k)) for k in (IDENTICAL, DIFFERS, DIVERGED, VISION_ONLY, ERROR)]
    lines.append("results        " + ", ".join(f"{k} {v}" for k, v in counts if v))
    changed = batch.decisions_changed
    what = "under the new parameters" if changed_params else "with the recorded parameters"
    changes = "changes its" if len(changed) == 1 else "change their"
    lines.append(
        f"decisions      {len(changed)} of {counted(n, 'flight')} {changes} decision {what}"
    )
    lines += [f"  {p}" for p in changed[:20]]
    if len(changed) > 20:
        lines.append(f"  … and {len(changed) - 20} more (see the table)")
    recorded = [r for r in batch.rows if r.get("photos") is not None]
    if recorded:
        photos = sum(r["photos"] for r in recorded)
        matched = sum(r["photos_matched"] for r in recorded)
        lines.append(
            f"photos         {matched} of {photos} match the target, in {len(recorded)} "
            f"recording{'s' if len(recorded) != 1 else ''} of uavtool record"
        )
    for r in batch.rows:
        if r.get("result") == ERROR:
            lines.append(f"error          {r['recording']}: {r.get('error')}")
    return "\n".join(lines)
