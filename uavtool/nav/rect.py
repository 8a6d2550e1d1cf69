"""The smallest-area rectangle around a footprint (convex hull + rotating calipers)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from uavtool.nav.errors import NavError
from uavtool.nav.geometry import Point, as_points, convex_hull

# Areas within this relative amount are a tie; the first hull edge wins, so the answer
# does not flip on last-bit differences between equivalent orientations.
_TIE_REL = 1e-9


def axis_heading_deg(east: float, north: float) -> float:
    """Heading of the line along ``(east, north)``, clockwise from north, folded into [0, 180)."""
    a = math.degrees(math.atan2(east, north)) % 180.0
    return 0.0 if a >= 180.0 or a == 0.0 else a


@dataclass(frozen=True, slots=True)
class Rect:
    """A rectangle on the ground, ENU metres.

    ``long_axis_deg`` is the heading of the long sides in [0, 180); ``length_m`` ≥
    ``width_m`` are the long and short side lengths.
    """

    center_en: tuple[float, float]
    long_axis_deg: float
    length_m: float
    width_m: float

    def axes(self) -> tuple[Point, Point]:
        """Unit vectors ``(along, across)``: the long axis and the axis 90° clockwise of it."""
        t = math.radians(self.long_axis_deg)
        s, c = math.sin(t), math.cos(t)
        return (s, c), (c, -s)

    def corners(self) -> tuple[Point, Point, Point, Point]:
        """The four corners, counter-clockwise."""
        (ax, ay), (nx, ny) = self.axes()
        cx, cy = self.center_en
        hl, hw = self.length_m / 2.0, self.width_m / 2.0

        def at(sa: float, sn: float) -> Point:
            return (cx + sa * hl * ax + sn * hw * nx, cy + sa * hl * ay + sn * hw * ny)

        return (at(-1.0, -1.0), at(-1.0, 1.0), at(1.0, 1.0), at(1.0, -1.0))

    @property
    def area_m2(self) -> float:
        return self.length_m * self.width_m


def _rect_from_frame(
    origin: Point, u: Point, lo_u: float, hi_u: float, lo_v: float, hi_v: float
) -> Rect:
    """The rectangle [lo_u, hi_u] × [lo_v, hi_v] in the frame at ``origin`` with x axis ``u``."""
    v = (-u[1], u[0])
    mu, mv = (lo_u + hi_u) / 2.0, (lo_v + hi_v) / 2.0
    center = (origin[0] + mu * u[0] + mv * v[0], origin[1] + mu * u[1] + mv * v[1])
    eu, ev = hi_u - lo_u, hi_v - lo_v
    hu, hv = axis_heading_deg(u[0], u[1]), axis_heading_deg(v[0], v[1])
    if abs(eu - ev) <= _TIE_REL * max(eu, ev):
        # A square: either axis is "long"; take the one nearer north for a stable answer.
        return Rect(center, min(hu, hv), max(eu, ev), min(eu, ev))
    if eu > ev:
        return Rect(center, hu, eu, ev)
    return Rect(center, hv, ev, eu)


def min_area_rect(points_en: Sequence[Sequence[float]] | Any) -> Rect:
    """The smallest-area rectangle enclosing ``points_en`` ((n, 2) east/north metres).

    One side of the optimum lies along a hull edge, so each edge is tried (rotating
    calipers, evaluated directly on the hull). Collinear input gives a width-0 rectangle,
    one distinct point a zero-size one. Raises NavError for no points.
    """
    pts = as_points(points_en, what="points_en")
    if not pts:
        raise NavError("min_area_rect needs at least one point")
    hull = convex_hull(pts)
    if len(hull) == 1:
        return Rect(hull[0], 0.0, 0.0, 0.0)
    best: tuple[float, Rect] | None = None
    n = len(hull)
    for i in range(n if n > 2 else 1):
        o, q = hull[i], hull[(i + 1) % n]
        dx, dy = q[0] - o[0], q[1] - o[1]
        norm = math.sqrt(dx * dx + dy * dy)
        u = (dx / norm, dy / norm)
        su = [(p[0] - o[0]) * u[0] + (p[1] - o[1]) * u[1] for p in hull]
        sv = [(p[1] - o[1]) * u[0] - (p[0] - o[0]) * u[1] for p in hull]
        lo_u, hi_u, lo_v, hi_v = min(su), max(su), min(sv), max(sv)
        area = (hi_u - lo_u) * (hi_v - lo_v)
        if best is None or area < best[0] - _TIE_REL * best[0]:
            best = (area, _rect_from_frame(o, u, lo_u, hi_u, lo_v, hi_v))
    assert best is not None
    return best[1]
