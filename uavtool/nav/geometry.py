"""Plane geometry on ``(east_m, north_m)`` tuples in plain float arithmetic.

Small, exact-where-possible predicates the rectangle and viewpoint planners share: convex
hull, point–polygon distance, segment and triangle intersection. Polygons are vertex
sequences (closed implicitly, either orientation); one or two vertices stand for a point
or a segment.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

from uavtool.nav.errors import NavError

Point = tuple[float, float]


def as_points(points: Any, *, what: str = "points") -> list[Point]:
    """``points`` ((n, 2) array or a sequence of pairs) as a list of float pairs."""
    rows = points.tolist() if hasattr(points, "tolist") else points
    out: list[Point] = []
    for i, p in enumerate(rows):
        if len(p) != 2:
            raise NavError(f"{what}[{i}] must be an (east, north) pair, got {p!r}")
        x, y = float(p[0]), float(p[1])
        if not (math.isfinite(x) and math.isfinite(y)):
            raise NavError(f"{what}[{i}] is not finite: {p!r}")
        out.append((x, y))
    return out


def cross(o: Point, a: Point, b: Point) -> float:
    """z of (a − o) × (b − o): > 0 when o → a → b turns left (counter-clockwise)."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def dist(a: Point, b: Point) -> float:
    dx, dy = a[0] - b[0], a[1] - b[1]
    return math.sqrt(dx * dx + dy * dy)


def convex_hull(points: Iterable[Point]) -> list[Point]:
    """Counter-clockwise hull without collinear vertices, starting at the lowest (x, y).

    Andrew's monotone chain; 1 or 2 vertices for degenerate input.
    """
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts
    lower: list[Point] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    upper: list[Point] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]
    return hull if len(hull) >= 2 else pts[:1]


def closest_on_segment(p: Point, a: Point, b: Point) -> Point:
    """The point of the closed segment ``a``–``b`` nearest ``p``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    den = dx * dx + dy * dy
    if den == 0.0:
        return a
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / den
    t = min(1.0, max(0.0, t))
    return (a[0] + t * dx, a[1] + t * dy)


def point_segment_distance(p: Point, a: Point, b: Point) -> float:
    """Distance from ``p`` to the closed segment ``a``–``b``."""
    return dist(p, closest_on_segment(p, a, b))


def point_in_polygon(p: Point, poly: Sequence[Point]) -> bool:
    """Whether ``p`` is strictly inside ``poly`` (even–odd rule; boundary may go either way)."""
    inside = False
    n = len(poly)
    for i in range(n):
        a, b = poly[i], poly[(i + 1) % n]
        if (a[1] > p[1]) != (b[1] > p[1]):
            x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            if p[0] < x:
                inside = not inside
    return inside


def _edges(poly: Sequence[Point]) -> list[tuple[Point, Point]]:
    n = len(poly)
    if n == 1:
        return [(poly[0], poly[0])]
    if n == 2:
        return [(poly[0], poly[1])]
    return [(poly[i], poly[(i + 1) % n]) for i in range(n)]


def point_polygon_distance(p: Point, poly: Sequence[Point]) -> float:
    """Distance from ``p`` to the polygon's area: 0 inside or on it."""
    if len(poly) >= 3 and point_in_polygon(p, poly):
        return 0.0
    return min(point_segment_distance(p, a, b) for a, b in _edges(poly))


def _on_segment(p: Point, a: Point, b: Point) -> bool:
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


def segments_intersect(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Whether the closed segments a–b and c–d share a point (touching counts)."""
    d1, d2 = cross(c, d, a), cross(c, d, b)
    d3, d4 = cross(a, b, c), cross(a, b, d)
    if ((d1 > 0.0 > d2) or (d1 < 0.0 < d2)) and ((d3 > 0.0 > d4) or (d3 < 0.0 < d4)):
        return True
    return (
        (d1 == 0.0 and _on_segment(a, c, d))
        or (d2 == 0.0 and _on_segment(b, c, d))
        or (d3 == 0.0 and _on_segment(c, a, b))
        or (d4 == 0.0 and _on_segment(d, a, b))
    )


def polygons_overlap(a: Sequence[Point], b: Sequence[Point]) -> bool:
    """Whether two polygons' closed areas share any point."""
    if len(a) < 3 or len(b) < 3:
        return False
    if any(segments_intersect(p, q, r, t) for p, q in _edges(a) for r, t in _edges(b)):
        return True
    return point_in_polygon(a[0], b) or point_in_polygon(b[0], a)


def _in_triangle(p: Point, tri: Sequence[Point]) -> bool:
    c1, c2, c3 = cross(tri[0], tri[1], p), cross(tri[1], tri[2], p), cross(tri[2], tri[0], p)
    return (c1 >= 0.0 and c2 >= 0.0 and c3 >= 0.0) or (c1 <= 0.0 and c2 <= 0.0 and c3 <= 0.0)


def triangle_hits_polygon(tri: Sequence[Point], poly: Sequence[Point]) -> bool:
    """Whether the closed triangle ``tri`` and the polygon's area share any point."""
    tri_edges = _edges(tri)
    for a, b in _edges(poly):
        if any(segments_intersect(a, b, c, d) for c, d in tri_edges):
            return True
    # No edges cross: one lies wholly inside the other (or they are apart).
    if _in_triangle(poly[0], tri):
        return True
    return len(poly) >= 3 and point_in_polygon(tri[0], poly)


def segment_polygon_distance(a: Point, b: Point, poly: Sequence[Point]) -> float:
    """Distance from the closed segment ``a``–``b`` to the polygon's area: 0 when they touch."""
    if len(poly) >= 3 and (
        point_in_polygon(a, poly) or any(segments_intersect(a, b, c, d) for c, d in _edges(poly))
    ):
        return 0.0
    ends = (point_polygon_distance(a, poly), point_polygon_distance(b, poly))
    return min(*ends, *(point_segment_distance(q, a, b) for q in poly))
