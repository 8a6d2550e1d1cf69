"""Visiting order for points of interest: nearest neighbour, then 2-opt on the open path."""

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


def _two_opt(start: Point, pts: list[Point], order: list[int]) -> list[int]:
    """Reverse sub-paths while that shortens the open path (start fixed, end free)."""
    n = len(order)
    improved = True
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
                    improved = True
                    a = pts[order[i]]
    return order


def visit_order(
    start_en: Sequence[float], points_en: Sequence[Sequence[float]] | Any
) -> tuple[int, ...]:
    """Indices of ``points_en`` ((n, 2) east/north metres) in the order to visit them from
    ``start_en``: nearest neighbour (ties to the lower index), improved by 2-opt moves
    (first improvement, scanned in index order) until none shortens the open path.
    Deterministic; never longer than the nearest-neighbour route."""
    start = as_points([start_en], what="start_en")[0]
    pts = as_points(points_en, what="points_en")
    return tuple(_two_opt(start, pts, _nearest_neighbour(start, pts)))


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
