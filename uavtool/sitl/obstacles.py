"""Obstacles the simulated vehicle can hit: vertical prisms in its local frame.

A :class:`Prism` is a simple polygon footprint (metres east/north of the vehicle's home, either
winding) extruded from ``base_m`` up to ``top_m`` (metres above home). A building made of
several blocks is several prisms sharing a name; a prism with ``base_m > 0`` is an overhang or
the roof of a tunnel. The SITL knows nothing of scenes: whoever starts it turns its world into
prisms (``uavtool.world.obstacles.scene_obstacles`` does it for a scene).

Distances are signed: positive outside, 0 on the surface, negative inside (minus the depth).
Plain ``math`` only, so that decisions made on them are the same on every machine; an
:class:`ObstacleField` precomputes edges and bounding boxes to keep the 50 Hz check cheap.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from uavtool.errors import InputError

# (x0, y0, dx, dy, 1/|d|²) per edge: a footprint edge from (x0, y0) to (x0 + dx, y0 + dy).
_Edge = tuple[float, float, float, float, float]


@dataclass(frozen=True, slots=True)
class Prism:
    """A vertical prism: ``footprint_en_m`` (≥ 3 (east, north) vertices in metres around the
    vehicle's home, a simple polygon of either winding) from ``base_m`` up to ``top_m``
    (metres above home). Raises InputError for a degenerate or non-finite prism."""

    name: str
    footprint_en_m: tuple[tuple[float, float], ...]
    base_m: float
    top_m: float

    def __post_init__(self) -> None:
        if len(self.footprint_en_m) < 3:
            raise InputError(f"obstacle {self.name!r}: a footprint needs at least 3 vertices")
        values = [v for point in self.footprint_en_m for v in point] + [self.base_m, self.top_m]
        if not all(math.isfinite(v) for v in values):
            raise InputError(f"obstacle {self.name!r}: coordinates must be finite")
        if not self.top_m > self.base_m:
            raise InputError(
                f"obstacle {self.name!r}: top ({self.top_m:g} m) must be above "
                f"base ({self.base_m:g} m)"
            )


def _edges(footprint_en_m: Sequence[tuple[float, float]]) -> tuple[_Edge, ...]:
    out = []
    for i, (x0, y0) in enumerate(footprint_en_m):
        x1, y1 = footprint_en_m[(i + 1) % len(footprint_en_m)]
        dx, dy = x1 - x0, y1 - y0
        len2 = dx * dx + dy * dy
        out.append((x0, y0, dx, dy, 1.0 / len2 if len2 > 0.0 else 0.0))
    return tuple(out)


def _footprint_distance_m(edges: tuple[_Edge, ...], east_m: float, north_m: float) -> float:
    """Signed horizontal distance from (east, north) to the footprint's outline (< 0 inside)."""
    best2 = math.inf
    inside = False
    for x0, y0, dx, dy, inv_len2 in edges:
        wx, wy = east_m - x0, north_m - y0
        t = (wx * dx + wy * dy) * inv_len2
        t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        ex, ey = wx - dx * t, wy - dy * t
        d2 = ex * ex + ey * ey
        best2 = min(best2, d2)
        # Even-odd crossing test on a ray towards +east: winding does not matter.
        if (y0 > north_m) != (y0 + dy > north_m) and east_m < x0 + (north_m - y0) * dx / dy:
            inside = not inside
    d = math.sqrt(best2)
    return -d if inside else d


def _extrude(horizontal_m: float, vertical_m: float) -> float:
    """Exact signed distance to a prism from the signed distances to its footprint (horizontal)
    and to its height slab (vertical): Euclidean outside both, the nearer face inside."""
    if horizontal_m > 0.0 and vertical_m > 0.0:
        return math.hypot(horizontal_m, vertical_m)
    return max(horizontal_m, vertical_m)


def prism_distance_m(prism: Prism, east_m: float, north_m: float, up_m: float) -> float:
    """Signed distance in metres from the point (east, north, up; metres around home) to the
    surface of ``prism``: > 0 outside, ≤ 0 inside. For one-off queries; the flight loop uses
    :meth:`ObstacleField.nearest`."""
    horizontal = _footprint_distance_m(_edges(prism.footprint_en_m), east_m, north_m)
    return _extrude(horizontal, max(prism.base_m - up_m, up_m - prism.top_m))


@dataclass(frozen=True, slots=True)
class _Prepared:
    prism: Prism
    edges: tuple[_Edge, ...]
    min_e: float
    max_e: float
    min_n: float
    max_n: float


class ObstacleField:
    """Prisms made ready for fast nearest-surface queries (edges and bounding boxes computed
    once; prisms whose box is farther than the best distance so far are skipped)."""

    def __init__(self, prisms: Sequence[Prism]) -> None:
        self.prisms = tuple(prisms)
        self._prepared = tuple(
            _Prepared(
                p,
                _edges(p.footprint_en_m),
                min(e for e, _ in p.footprint_en_m),
                max(e for e, _ in p.footprint_en_m),
                min(n for _, n in p.footprint_en_m),
                max(n for _, n in p.footprint_en_m),
            )
            for p in self.prisms
        )

    def __len__(self) -> int:
        return len(self.prisms)

    def nearest(self, east_m: float, north_m: float, up_m: float) -> tuple[float, Prism | None]:
        """(signed distance in metres to the nearest prism surface, that prism) from the point
        (east, north, up; metres around home); ``(inf, None)`` when there are no prisms.

        Inside overlapping or touching prisms the distance is negative but may understate the
        depth (it is the nearest face of one prism, not of their union); outside it is exact.
        """
        best = math.inf
        best_prism: Prism | None = None
        for p in self._prepared:
            # The bounding box is a lower bound on the distance: skip prisms that cannot win.
            dx = max(p.min_e - east_m, east_m - p.max_e, 0.0)
            dy = max(p.min_n - north_m, north_m - p.max_n, 0.0)
            prism = p.prism
            dz = max(prism.base_m - up_m, up_m - prism.top_m)
            dz_out = dz if dz > 0.0 else 0.0
            if dx * dx + dy * dy + dz_out * dz_out >= best * best:
                continue
            d = _extrude(_footprint_distance_m(p.edges, east_m, north_m), dz)
            if d < best:
                best, best_prism = d, prism
        return best, best_prism

    def first_above(
        self, east_m: float, north_m: float, *, from_up_m: float, to_up_m: float, radius_m: float
    ) -> tuple[Prism, float] | None:
        """What a sphere of ``radius_m`` rising straight up at (east, north) from ``from_up_m``
        to ``to_up_m`` (metres above home) would touch first: ``(prism, signed distance from the
        path)``, the prism with the lowest base among those nearer than ``radius_m`` to the path;
        None when the path is clear."""
        low, high = min(from_up_m, to_up_m), max(from_up_m, to_up_m)
        hit: tuple[Prism, float] | None = None
        for p in self._prepared:
            prism = p.prism
            if hit is not None and prism.base_m >= hit[0].base_m:
                continue
            # max(base − z, z − top) is V-shaped in z: its least value on the path is at the
            # point of the path nearest the slab's middle.
            z = min(max((prism.base_m + prism.top_m) / 2.0, low), high)
            dz = max(prism.base_m - z, z - prism.top_m)
            d = _extrude(_footprint_distance_m(p.edges, east_m, north_m), dz)
            if d < radius_m:
                hit = (prism, d)
        return hit
