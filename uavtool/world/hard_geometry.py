"""Plane geometry for the hard-scene generator: rotation, distances, polygon checks, chirality.

Pure functions of ``(east_m, north_m)`` points in plain Python floats (no randomness), so
:mod:`uavtool.world.hard` stays deterministic.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from uavtool.world.polygon import normalise_ring, signed_area

Point = tuple[float, float]
Ring = tuple[Point, ...]


def rotation(angle: float) -> Callable[[Point], Point]:
    """The map turning a point counter-clockwise by ``angle`` radians about the origin."""
    c, s = math.cos(angle), math.sin(angle)
    return lambda p: (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _cross3(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def point_segment_m(p: Point, a: Point, b: Point) -> float:
    """Distance from ``p`` to the segment ``a``–``b``, metres."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)


def well_formed(ring: Sequence[Point], *, edge_m: float = 0.5, gap_m: float = 0.3) -> bool:
    """Simple, every edge at least ``edge_m`` long, non-adjacent edges ``gap_m`` apart."""
    n = len(ring)
    edges = [(ring[i], ring[(i + 1) % n]) for i in range(n)]
    if any(math.dist(a, b) < edge_m for a, b in edges):
        return False
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through the closing vertex
            (a, b), (c, d) = edges[i], edges[j]
            d1, d2 = _cross3(c, d, a), _cross3(c, d, b)
            d3, d4 = _cross3(a, b, c), _cross3(a, b, d)
            if d1 * d2 < 0.0 and d3 * d4 < 0.0:  # a proper crossing; touching is in `near`
                return False
            near = min(
                point_segment_m(a, c, d),
                point_segment_m(b, c, d),
                point_segment_m(c, a, b),
                point_segment_m(d, a, b),
            )
            if near < gap_m:
                return False
    return True


def inside(p: Point, ring: Sequence[Point]) -> bool:
    """Whether ``p`` is inside the ring (even–odd ray casting)."""
    odd = False
    n = len(ring)
    for i in range(n):
        (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % n]
        if (y0 > p[1]) != (y1 > p[1]) and p[0] < x0 + (p[1] - y0) * (x1 - x0) / (y1 - y0):
            odd = not odd
    return odd


def is_chiral(ring: Ring) -> bool:
    """Whether the ring's mirror image stays at least 10 % of its size away from it however
    it is turned: a mirror decoy of a (nearly) symmetric shape would be a plain copy."""
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    limit_m = 0.1 * max(max(xs) - min(xs), max(ys) - min(ys))
    return _mirror_gap_m(ring, limit_m) >= limit_m


def _mirror_gap_m(ring: Ring, limit_m: float) -> float:
    """The least discrete Hausdorff distance between the ring and its mirror image, metres,
    over the turns that lay an edge of one along an edge of the other, centroids together;
    capped at ``limit_m`` (which lets most turns stop early)."""
    a, b = _about_centroid(ring), _about_centroid(normalise_ring([(-x, y) for x, y in ring]))
    best = limit_m
    for i in range(len(a)):
        ha = _heading(a[i], a[(i + 1) % len(a)])
        for j in range(len(b)):
            turn = rotation(_heading(b[j], b[(j + 1) % len(b)]) - ha)
            moved = [turn(p) for p in a]
            best = min(best, _hausdorff_m(moved, b, best), _hausdorff_m(b, moved, best))
    return best


def _heading(a: Point, b: Point) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def _about_centroid(ring: Sequence[Point]) -> Ring:
    area6 = 6.0 * signed_area(ring)
    n = len(ring)
    cx = cy = 0.0
    for i in range(n):
        (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % n]
        w = x0 * y1 - x1 * y0
        cx, cy = cx + (x0 + x1) * w, cy + (y0 + y1) * w
    return tuple((x - cx / area6, y - cy / area6) for x, y in ring)


def _hausdorff_m(a: Sequence[Point], b: Sequence[Point], stop_m: float) -> float:
    """Farthest vertex of ``a`` from ``b``'s boundary, metres; stops at ``stop_m``."""
    n = len(b)
    worst = 0.0
    for p in a:
        worst = max(worst, min(point_segment_m(p, b[k], b[(k + 1) % n]) for k in range(n)))
        if worst >= stop_m:
            return stop_m
    return worst


def segment_distance_m(a: Point, b: Point, c: Point, d: Point) -> float:
    """Distance between the segments ``a``–``b`` and ``c``–``d``, metres (0 if they cross)."""
    d1, d2 = _cross3(c, d, a), _cross3(c, d, b)
    d3, d4 = _cross3(a, b, c), _cross3(a, b, d)
    if d1 * d2 < 0.0 and d3 * d4 < 0.0:
        return 0.0
    return min(
        point_segment_m(a, c, d),
        point_segment_m(b, c, d),
        point_segment_m(c, a, b),
        point_segment_m(d, a, b),
    )


def ring_distance_m(a: Sequence[Point], b: Sequence[Point]) -> float:
    """Least distance between two polygons, metres: 0 if they overlap or one holds the other."""
    if inside(a[0], b) or inside(b[0], a):
        return 0.0
    na, nb = len(a), len(b)
    return min(
        segment_distance_m(a[i], a[(i + 1) % na], b[j], b[(j + 1) % nb])
        for i in range(na)
        for j in range(nb)
    )


def rectilinear(ring: Sequence[Point]) -> bool:
    """Whether every edge runs exactly east–west or north–south (a plan before it is turned)."""
    n = len(ring)
    return all(
        ring[i][0] == ring[(i + 1) % n][0] or ring[i][1] == ring[(i + 1) % n][1] for i in range(n)
    )


def convex_corners(ring: Sequence[Point]) -> list[bool]:
    """Per vertex of a counter-clockwise ring: whether it turns left (a convex corner)."""
    n = len(ring)
    return [_cross3(ring[k - 1], ring[k], ring[(k + 1) % n]) > 0.0 for k in range(n)]


def inset_ring(ring: Sequence[Point], widths: Sequence[float]) -> Ring | None:
    """The counter-clockwise ring with edge ``k`` moved inwards by ``widths[k]`` metres (vertex
    ``k`` of the result answers vertex ``k``); None if two neighbouring edges are parallel or
    an edge turns round (the ring is too narrow for those widths)."""
    n = len(ring)
    lines: list[tuple[Point, Point]] = []
    for k in range(n):
        (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % n]
        length = math.hypot(x1 - x0, y1 - y0)
        dx, dy = (x1 - x0) / length, (y1 - y0) / length
        lines.append(((x0 - widths[k] * dy, y0 + widths[k] * dx), (dx, dy)))  # left: inwards
    out: list[Point] = []
    for k in range(n):
        (p, d), (q, e) = lines[k - 1], lines[k]
        den = d[0] * e[1] - d[1] * e[0]
        if abs(den) < 1e-9:
            return None
        t = ((q[0] - p[0]) * e[1] - (q[1] - p[1]) * e[0]) / den
        out.append((p[0] + t * d[0], p[1] + t * d[1]))
    for k in range(n):  # every edge keeps its direction (none flipped over)
        (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % n]
        (u0, v0), (u1, v1) = out[k], out[(k + 1) % n]
        if (x1 - x0) * (u1 - u0) + (y1 - y0) * (v1 - v0) <= 0.0:
            return None
    return tuple(out)


def star_centre(ring: Sequence[Point], steps: int = 12) -> Point | None:
    """A point inside the ring from which every vertex is seen (the ring is star-shaped about
    it), the one farthest from the edges of a grid of ``steps`` × ``steps`` over its bounding
    box; None if no grid point sees them all. No randomness: a function of the ring."""
    n = len(ring)
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    best: Point | None = None
    best_m = 0.0
    for i in range(1, steps):
        for j in range(1, steps):
            c = (
                min(xs) + (max(xs) - min(xs)) * i / steps,
                min(ys) + (max(ys) - min(ys)) * j / steps,
            )
            if not inside(c, ring):
                continue
            clear = min(point_segment_m(c, ring[k], ring[(k + 1) % n]) for k in range(n))
            if clear > best_m and _sees_all(c, ring):
                best, best_m = c, clear
    return best


def _sees_all(c: Point, ring: Sequence[Point]) -> bool:
    n = len(ring)
    for k in range(n):
        for m in range(n):
            if m in (k, (k - 1) % n):
                continue  # the edges at ring[k] meet the sight line there
            if segment_distance_m(c, ring[k], ring[m], ring[(m + 1) % n]) < 1e-6:
                return False
    return True
