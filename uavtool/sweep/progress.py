"""Progress of a sweep or a batch replay: counts, rate and ETA, and a one-line bar for a
terminal. The library reports through a callback; the command line draws."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Progress:
    """``done`` counts the tasks finished in this run; ``skipped`` those done before
    (``--resume``), which are not part of the rate."""

    done: int
    total: int
    skipped: int = 0
    errors: int = 0
    elapsed_s: float = 0.0

    @property
    def rate_per_min(self) -> float:
        return 60.0 * self.done / self.elapsed_s if self.elapsed_s > 0 and self.done else 0.0

    @property
    def eta_s(self) -> float | None:
        """Seconds left at the rate so far (None before the first task finishes)."""
        if not self.done:
            return None
        left = self.total - self.skipped - self.done
        return max(left, 0) * self.elapsed_s / self.done


ProgressCallback = Callable[[Progress], None]


def format_progress(p: Progress, *, noun: str = "flights", width: int = 24) -> str:
    """``[#########.........] 12/60 flights, 1 error, 4.1/min, ETA 11m42s``."""
    finished = p.done + p.skipped
    fill = round(width * finished / p.total) if p.total else width
    parts = [f"[{'#' * fill}{'.' * (width - fill)}] {finished}/{p.total} {noun}"]
    if p.skipped:
        parts.append(f"{p.skipped} resumed")
    if p.errors:
        parts.append(f"{p.errors} error{'s' if p.errors != 1 else ''}")
    if p.done:
        parts.append(f"{p.rate_per_min:.1f}/min")
    eta = p.eta_s
    parts.append("ETA --" if eta is None else f"ETA {format_duration(eta)}")
    return ", ".join(parts)


def format_duration(seconds: float) -> str:
    s = round(seconds)
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{s % 3600 // 60:02d}m"
