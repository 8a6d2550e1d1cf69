"""Visiting order for points of interest: nearest neighbour, then local improvement.

The path is open (start fixed, end free). 2-opt alone cannot move the far end of a row to
its front (a start in the middle of a line of buildings), so Or-opt moves — a run of up
to three points cut out and put back elsewhere, either way round — run alongside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from uavtool.nav.errors import NavError
from uavtool.nav.geometry import Point, as_points, dist

# A 2-opt move must shorten the route by more than this (metres) to be taken, so float
# noise cannot make two equal routes swap back and forth.
_MIN_GAIN_M = 1e-9


def _nearest_neighbour(start: Point, pts: list[Point]) -> list[int]:
    left = list(range(len(pts)))
    order: list[int] = []
    here = start
    while left:
        best = left[0]
        best_d = dist(here, pts[best])
        for i in left[1:]:
            d = dist(here, pts[i])
            if d < best_d:  # strict: ties keep the lowest index
                best, best_d = i, d
        left.remove(best)
        order.append(best)
        here = pts[best]
    return order


def _two_opt(start: Point, pts: list[Point], order: list[int]) -> bool:
    """Reverse sub-paths while that shortens the path; whether anything changed."""
    n = len(order)
    changed, improved = False, True
    while improved:
        improved = False
        for i in range(n - 1):
            prev = start if i == 0 else pts[order[i - 1]]
            a = pts[order[i]]
            for j in range(i + 1, n):
                b = pts[order[j]]
                before = dist(prev, a)
                after = dist(prev, b)
                if j + 1 < n:
                    nxt = pts[order[j + 1]]
                    before += dist(b, nxt)
                    after += dist(a, nxt)
                if after < before - _MIN_GAIN_M:
                    order[i : j + 1] = order[i : j + 1][::-1]
                    changed = improved = True
                    a = pts[order[i]]
    return changed


def _or_opt_once(start: Point, pts: list[Point], order: list[int]) -> bool:
    """Apply the first Or-opt move (scan order) that shortens the path; whether one did."""
    n = len(order)

    def at(k: int) -> Point:  # route position k: 0 is the start, k ≥ 1 is order[k - 1]
        return start if k == 0 else pts[order[k - 1]]

    def gap(a: Point, b: Point | None) -> float:  # an edge to "no next point" is free
        return 0.0 if b is None else dist(a, b)

    for size in (1, 2, 3):
        for i in range(1, n - size + 2):
            j = i + size - 1
            prev, first, last = at(i - 1), at(i), at(j)
            nxt = at(j + 1) if j < n else None
            removed = dist(prev, first) + gap(last, nxt) - gap(prev, nxt)
            rest = [k for k in range(n + 1) if not i <= k <= j]
            for p, k in enumerate(rest):
                if k == i - 1:
                    continue  # putting it back where it was
                a = at(k)
                b = at(rest[p + 1]) if p + 1 < len(rest) else None
                for x, y, flip in ((first, last, False), (last, first, True)):
                    added = dist(a, x) + gap(y, b) - gap(a, b)
                    if added < removed - _MIN_GAIN_M:
                        run = order[i - 1 : j]
                        if flip:
                            run.reverse()
                        kept = [order[q - 1] for q in rest if q != 0]
                        cut = sum(1 for q in rest[: p + 1] if q != 0)
                        order[:] = kept[:cut] + run + kept[cut:]
                        return True
    return False


def visit_order(
    start_en: Sequence[float], points_en: Sequence[Sequence[float]] | Any
) -> tuple[int, ...]:
    """Indices of ``points_en`` ((n, 2) east/north metres) in the order to visit them from
    ``start_en``: nearest neighbour (ties to the lower index), then 2-opt and Or-opt moves
    (first improvement, scanned in index order) until none shortens the open path.
    Deterministic; never longer than the nearest-neighbour route."""
    start = as_points([start_en], what="start_en")[0]
    pts = as_points(points_en, what="points_en")
    order = _nearest_neighbour(start, pts)
    _two_opt(start, pts, order)
    while _or_opt_once(start, pts, order):
        _two_opt(start, pts, order)
    return tuple(order)


def route_length_m(
    start_en: Sequence[float], points_en: Sequence[Sequence[float]] | Any, order: Sequence[int]
) -> float:
    """Length of the open path start → points_en[order[0]] → … (metres, summed in order)."""
    start = as_points([start_en], what="start_en")[0]
    pts = as_points(points_en, what="points_en")
    total, here = 0.0, start
    for k in order:
        if not 0 <= k < len(pts):
            raise NavError(f"route index {k} is out of range for {len(pts)} points")
        total += dist(here, pts[k])
        here = pts[k]
    return total
