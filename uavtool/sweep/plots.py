"""One PNG per key figure of a sweep: the success rate per condition, the IoU distribution and
the score margins. Needs matplotlib (``pip install 'uavtool[plots]'``); without it the sweep
still writes its table and summary and says the plots were skipped."""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from uavtool.errors import UavtoolError
from uavtool.sweep.summary import Rate, Summary

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class PlotsUnavailableError(UavtoolError):
    """matplotlib is not installed."""


def write_plots(summary: Summary, folder: Path) -> tuple[Path, ...]:
    """The PNGs written into ``folder``; raises PlotsUnavailableError without matplotlib."""
    try:
        from matplotlib.figure import Figure  # noqa: PLC0415 - an optional extra
    except ImportError:
        raise PlotsUnavailableError(
            "plots skipped: matplotlib is not installed (pip install 'uavtool[plots]')"
        ) from None
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for key, rates in summary.conditions:
        name = re.sub(r"[^A-Za-z0-9._]+", "-", key)
        fig = _success(Figure(figsize=(7, 4)), key, rates, searched=summary.searched)
        written.append(_save(fig, folder / f"success-{name}.png"))
    if summary.ious:
        fig = _histogram(Figure(figsize=(6, 4)), summary.ious, "model IoU with the target building")
        written.append(_save(fig, folder / "iou.png"))
    if summary.margins:
        fig = _histogram(
            Figure(figsize=(6, 4)),
            summary.margins,
            "score margin: target minus best other building",
            mark_zero=True,
        )
        written.append(_save(fig, folder / "margin.png"))
    return tuple(written)


def _success(fig: Figure, key: str, rates: tuple[Rate, ...], *, searched: bool) -> Figure:
    ax = fig.add_subplot()
    xs = range(len(rates))
    correct = [r.correct / r.flights for r in rates]
    completed = [r.completed / r.flights for r in rates]
    if searched:
        ax.bar([x - 0.2 for x in xs], correct, width=0.4, label="correct match")
        ax.bar([x + 0.2 for x in xs], completed, width=0.4, label="completed (model built)")
    else:  # another mission: whether it completed is all the table knows
        ax.bar(list(xs), completed, width=0.4, label="completed")
    ax.set_xticks(list(xs), [f"{r.value}\n({r.flights})" for r in rates], fontsize=8)
    ax.set_ylim(0.0, 1.05)
    ax.set_ylabel("fraction of flights")
    ax.set_title(f"success rate by {key}")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    return fig


def _histogram(
    fig: Figure, values: tuple[float, ...], title: str, *, mark_zero: bool = False
) -> Figure:
    ax = fig.add_subplot()
    ax.hist(values, bins=min(30, max(5, len(values) // 3)))
    if mark_zero:
        ax.axvline(0.0, color="red", linewidth=1)
    ax.set_xlabel(title)
    ax.set_ylabel("flights")
    ax.set_title(f"{title} ({len(values)} flights)")
    fig.tight_layout()
    return fig


def _save(fig: Figure, path: Path) -> Path:
    fig.savefig(path, dpi=100)
    return path
