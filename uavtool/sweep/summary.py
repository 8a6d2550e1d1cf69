"""What a sweep's table says: outcomes, correct matches overall and per condition (each input
that varies), the IoU of the models, and the score margin between the target and the best
other building photographed."""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

from uavtool.terminal import counted

_MAX_GROUPS = 8  # a numeric input with more distinct values is binned
_BINS = 5


@dataclass(frozen=True, slots=True)
class Rate:
    """Flights with one value (or bin) of a condition: how many matched the right building,
    and how many completed (right building matched, model built)."""

    value: str
    flights: int
    correct: int
    completed: int
    time_median_s: float | None = None
    """The median vehicle time of these flights (what a fleet buys, by ``vehicles``)."""


@dataclass(frozen=True, slots=True)
class Summary:
    flights: int
    planned: int
    statuses: tuple[tuple[str, int], ...]
    correct: int
    errors: int
    models: int
    ious: tuple[float, ...]
    margins: tuple[float, ...]
    clearance_min_m: float | None
    flight_time_median_s: float | None
    wall_total_s: float
    conditions: tuple[tuple[str, tuple[Rate, ...]], ...]
    searched: bool = True
    """The flights flew the built-in search (else matches and models mean nothing)."""
    closest_approach_m: float | None = None
    """Fleets: the least distance between two vehicles of any flight."""
    breaches: int = 0
    """Fleets: flights whose vehicles came closer than their separation."""

    def to_json(self) -> dict[str, Any]:
        data = asdict(self)
        data["iou"] = _stats(self.ious)
        data["margin"] = _stats(self.margins)
        del data["ious"], data["margins"]
        return data


def summarise(
    rows: Sequence[dict[str, Any]],
    *,
    input_keys: Sequence[str],
    planned: int,
    searched: bool = True,
) -> Summary:
    counts: dict[str, int] = {}
    for r in rows:
        counts[str(r["status"])] = counts.get(str(r["status"]), 0) + 1
    clearances = [float(r["clearance_m"]) for r in rows if r.get("clearance_m") is not None]
    times = [float(r["flight_time_s"]) for r in rows if r.get("flight_time_s")]
    approaches = [
        float(r["closest_approach_m"]) for r in rows if r.get("closest_approach_m") is not None
    ]
    return Summary(
        flights=len(rows),
        planned=planned,
        statuses=tuple(sorted(counts.items())),
        correct=sum(bool(r.get("correct")) for r in rows),
        errors=counts.get("error", 0),
        models=sum(bool(r.get("model_built")) for r in rows),
        ious=tuple(sorted(float(r["iou"]) for r in rows if r.get("iou") is not None)),
        margins=tuple(sorted(float(r["margin"]) for r in rows if r.get("margin") is not None)),
        clearance_min_m=min(clearances) if clearances else None,
        flight_time_median_s=statistics.median(times) if times else None,
        wall_total_s=sum(float(r.get("wall_s") or 0.0) for r in rows),
        conditions=tuple(
            (key, rates)
            for key in ("scene", *input_keys)
            if len(rates := _rates(rows, key, searched)) > 1
        ),
        searched=searched,
        closest_approach_m=min(approaches) if approaches else None,
        breaches=sum(
            1
            for r in rows
            if r.get("closest_approach_m") is not None
            and float(r["closest_approach_m"]) < float(r.get("separation_m") or 0.0)
        ),
    )


def _rates(rows: Sequence[dict[str, Any]], key: str, searched: bool) -> tuple[Rate, ...]:
    labels, order = _labels([r.get(key) for r in rows], by_kind=key == "scene")
    groups: dict[str, list[dict[str, Any]]] = {label: [] for label in order}
    for label, row in zip(labels, rows, strict=True):
        groups[label].append(row)
    return tuple(
        Rate(
            label,
            len(group),
            sum(bool(r.get("correct")) for r in group),
            sum(
                (bool(r.get("correct")) or not searched) and r.get("status") == "completed"
                for r in group
            ),
            _median([float(r["flight_time_s"]) for r in group if r.get("flight_time_s")]),
        )
        for label, group in groups.items()
        if group
    )


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def _labels(values: list[Any], *, by_kind: bool) -> tuple[list[str], list[str]]:
    """A group label per value, and the labels in ascending order of value."""
    distinct = sorted({v for v in values if v is not None}, key=lambda v: (str(type(v)), v))
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in distinct)
    if numeric and len(distinct) > _MAX_GROUPS:
        lo, hi = float(distinct[0]), float(distinct[-1])
        width = (hi - lo) / _BINS
        names = [f"{lo + i * width:.3g}–{lo + (i + 1) * width:.3g}" for i in range(_BINS)]
        return [
            "none" if v is None else names[min(int((float(v) - lo) / width), _BINS - 1)]
            for v in values
        ], [*names, "none"]
    if by_kind and len(distinct) > _MAX_GROUPS:
        kinds = [str(v).split(":")[0] for v in values]
        return kinds, sorted(set(kinds))
    return [_text(v) for v in values], [*(_text(v) for v in distinct), "none"]


def _text(value: Any) -> str:
    if isinstance(value, float) and value.is_integer():
        return f"{value:g}"
    return "none" if value is None else str(value)


def _stats(values: Sequence[float]) -> dict[str, float] | None:
    if not values:
        return None
    ordered = sorted(values)
    return {
        "n": len(ordered),
        "min": ordered[0],
        "p10": ordered[int(0.1 * (len(ordered) - 1))],
        "median": statistics.median(ordered),
        "max": ordered[-1],
    }


def _pct(k: int, n: int) -> str:
    return f"{k}/{n} ({100.0 * k / n:.0f} %)" if n else "0/0"


def format_summary(s: Summary) -> str:
    """The summary as printed and written to ``summary.txt``."""
    n = s.flights
    lines = [f"flights        {n} of {s.planned}" + ("" if n == s.planned else " (incomplete)")]
    lines.append("outcomes       " + ", ".join(f"{k} {v}" for k, v in s.statuses))
    if s.searched:
        lines.append(f"correct match  {_pct(s.correct, n)}")
        lines.append(f"model built    {_pct(s.models, n)}")
    iou = _stats(s.ious)
    if iou is not None:
        lines.append(
            f"model IoU      median {iou['median']:.3f}, 10th percentile {iou['p10']:.3f}, "
            f"worst {iou['min']:.3f}"
        )
    margin = _stats(s.margins)
    if margin is not None:
        at_risk = sum(m <= 0 for m in s.margins)
        lines.append(
            f"score margin   median {margin['median']:+.3f}, worst {margin['min']:+.3f} "
            f"(target minus best other building; {counted(at_risk, 'flight')} ≤ 0)"
        )
    if s.clearance_min_m is not None:
        lines.append(f"clearance      {s.clearance_min_m:.2f} m at the closest")
    if s.flight_time_median_s is not None:
        lines.append(f"flight time    median {s.flight_time_median_s:.1f} s (vehicle)")
    if s.closest_approach_m is not None:
        lines.append(
            f"separation     {s.closest_approach_m:.2f} m between two vehicles at the closest; "
            f"{counted(s.breaches, 'flight')} closer than its separation"
        )
    if s.errors:
        lines.append(f"errors         {counted(s.errors, 'flight')} raised (see the error column)")
    for key, rates in s.conditions:
        lines.append(f"by {key}:")
        lines += [
            f"  {r.value:<22} "
            + (f"correct {_pct(r.correct, r.flights):<16} " if s.searched else "")
            + f"completed {_pct(r.completed, r.flights)}"
            + (
                f"  median {r.time_median_s:.0f} s (vehicle)"
                if key == "vehicles" and r.time_median_s is not None
                else ""
            )
            for r in rates
        ]
    return "\n".join(lines)
