"""Building plans for the hard-scene generator: footprint shapes, stepped towers, arches, copies.

A :class:`Plan` is a building in its own frame, before :mod:`uavtool.world.hard` turns,
places and colours it. Only ``rng.random()`` feeds the draws (see that module's doc).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from uavtool.world.generator import _index
from uavtool.world.hard_geometry import (
    Point,
    Ring,
    convex_corners,
    inset_ring,
    inside,
    point_segment_m,
    rectilinear,
    segment_distance_m,
    star_centre,
    well_formed,
)
from uavtool.world.polygon import normalise_ring, signed_area

if TYPE_CHECKING:
    from uavtool.world.hard import HardOptions


@dataclass(frozen=True, slots=True)
class Part:
    """One block of a plan: a footprint ring between two heights, metres."""

    ring: Ring
    base_m: float
    top_m: float


@dataclass(frozen=True, slots=True)
class Plan:
    """A building in its own frame (origin near its middle) before it is turned and placed."""

    shape: str
    kind: str
    outline: Ring  # seen from above: every part's footprint lies inside it
    parts: tuple[Part, ...]
    yard: Ring | None = None  # a courtyard's open yard (courtyard_plan's: vertex k answers
    # the outline's k)


def uniform(rng: random.Random, lo: float, hi: float) -> float:
    """A draw in ``[lo, hi)`` from one ``rng.random()``."""
    return lo + (hi - lo) * rng.random()


def _centred(ring: Sequence[Point], kernel: Point) -> tuple[Ring, Point]:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return tuple((x - cx, y - cy) for x, y in ring), (kernel[0] - cx, kernel[1] - cy)


# Each maker returns a counter-clockwise ring and a point it is star-shaped about (shrinking
# the ring towards that point keeps it inside: how stepped tiers are made). The U has none.
def _rectangle(rng: random.Random) -> tuple[Ring, Point]:
    w, h = uniform(rng, 4.0, 12.0), uniform(rng, 4.0, 12.0)
    return _centred([(0, 0), (w, 0), (w, h), (0, h)], (w / 2.0, h / 2.0))


def _ell(rng: random.Random) -> tuple[Ring, Point]:
    w, h = uniform(rng, 6.0, 13.0), uniform(rng, 6.0, 13.0)
    a, b = w * uniform(rng, 0.3, 0.6), h * uniform(rng, 0.3, 0.6)
    return _centred([(0, 0), (w, 0), (w, b), (a, b), (a, h), (0, h)], (a / 2.0, b / 2.0))


def _tee(rng: random.Random) -> tuple[Ring, Point]:
    w, h = uniform(rng, 6.0, 13.0), uniform(rng, 6.0, 13.0)
    stem, bar = w * uniform(rng, 0.25, 0.45), h * uniform(rng, 0.25, 0.45)
    x0 = (w - stem) * uniform(rng, 0.15, 0.85)  # the stem off-centre: no mirror symmetry
    x1 = x0 + stem
    ring = [(x0, 0), (x1, 0), (x1, h - bar), (w, h - bar), (w, h), (0, h), (0, h - bar)]
    return _centred([*ring, (x0, h - bar)], ((x0 + x1) / 2.0, h - bar / 2.0))


def _you_params(rng: random.Random, lo: float) -> tuple[float, float, float, float, float]:
    w, h = uniform(rng, lo, 13.0), uniform(rng, lo, 13.0)
    return (
        w,
        h,
        w * uniform(rng, 0.18, 0.32),
        w * uniform(rng, 0.18, 0.32),
        h * uniform(rng, 0.25, 0.45),
    )


def _you_ring(w: float, h: float, a1: float, a2: float, floor: float) -> list[Point]:
    return [(0, 0), (w, 0), (w, h), (w - a2, h), (w - a2, floor), (a1, floor), (a1, h), (0, h)]


def _you(rng: random.Random) -> tuple[Ring, Point]:
    w, h, a1, a2, floor = _you_params(rng, 6.0)
    return _centred(_you_ring(w, h, a1, a2, floor), (w / 2.0, floor / 2.0))


def _cross(rng: random.Random) -> tuple[Ring, Point]:
    w, h = uniform(rng, 6.0, 13.0), uniform(rng, 6.0, 13.0)
    a, b = w * uniform(rng, 0.12, 0.25), h * uniform(rng, 0.12, 0.25)  # half-widths of the two bars
    # the crossing off-centre, every arm at least 15 % of the size long
    cx, cy = (
        0.15 * w + a + (0.7 * w - 2 * a) * rng.random(),
        0.15 * h + b + (0.7 * h - 2 * b) * rng.random(),
    )
    x0, x1, y0, y1 = cx - a, cx + a, cy - b, cy + b
    ring = [(x0, 0), (x1, 0), (x1, y0), (w, y0), (w, y1), (x1, y1), (x1, h), (x0, h), (x0, y1)]
    return _centred([*ring, (0, y1), (0, y0), (x0, y0)], (cx, cy))


def _radial(rng: random.Random, *, concave: bool) -> tuple[Ring, Point]:
    n = 5 + _index(rng, 4) if not concave else 6 + 2 * _index(rng, 3)
    r = uniform(rng, 2.5, 6.5)
    step = 2.0 * math.pi / n
    angles = [k * step + 0.5 * step * rng.random() for k in range(n)]  # increasing: simple
    # a star alternates outer and inner radii; a convex ring keeps to one circle (its gaps
    # are all under 180°)
    radii = [r if k % 2 == 0 or not concave else r * uniform(rng, 0.45, 0.7) for k in range(n)]
    ring = [(radii[k] * math.cos(a), radii[k] * math.sin(a)) for k, a in enumerate(angles)]
    return _centred(ring, (0.0, 0.0))


_MAKERS: dict[str, Callable[[random.Random], tuple[Ring, Point]]] = {
    "rectangle": _rectangle,
    "L": _ell,
    "T": _tee,
    "U": _you,
    "cross": _cross,
    "convex": lambda rng: _radial(rng, concave=False),
    "concave": lambda rng: _radial(rng, concave=True),
}
SHAPES = tuple(_MAKERS)
ARCHES = ("bridge", "L", "U")


def _height(rng: random.Random, o: HardOptions, lo_m: float = 0.0) -> float:
    lo = min(max(o.min_height_m, lo_m), o.max_height_m)
    return round(uniform(rng, lo, o.max_height_m), 1)


def plain_or_stepped(rng: random.Random, o: HardOptions, shape: str) -> Plan:
    """One block of a :data:`SHAPES` footprint, or (``stepped_p``) two or three shrinking
    tiers of it; a U is always one block."""
    ring, kernel = _MAKERS[shape](rng)
    if shape == "U" or rng.random() >= o.stepped_p:
        return Plan(shape, "plain", ring, (Part(ring, 0.0, _height(rng, o)),))
    top = _height(rng, o, 6.0)
    if rng.random() < 0.4:  # three tiers
        t1 = top * uniform(rng, 0.3, 0.5)
        tops = [t1, t1 + (top - t1) * uniform(rng, 0.4, 0.7), top]
        f1 = uniform(rng, 0.5, 0.8)
        scales = [1.0, f1, f1 * uniform(rng, 0.55, 0.8)]
    else:
        tops, scales = [top * uniform(rng, 0.4, 0.7), top], [1.0, uniform(rng, 0.5, 0.8)]
    kx, ky = kernel
    parts, base = [], 0.0
    for t, f in zip(tops, scales, strict=True):
        tier = tuple((kx + f * (x - kx), ky + f * (y - ky)) for x, y in ring)
        parts.append(Part(tier, base, round(t, 1)))
        base = round(t, 1)
    return Plan(shape, "stepped", ring, tuple(parts))


def arch_plan(rng: random.Random, o: HardOptions, shape: str) -> Plan:
    """Two pillars (base 0 up to the clearance) and a block resting on both (up to the top);
    ``shape`` is one of :data:`ARCHES`."""
    clearance = uniform(rng, 2.5, 4.5)
    if max(o.min_height_m, clearance + 2.0) > o.max_height_m:  # too low for a 2 m deck
        clearance = 0.5 * o.max_height_m
    top = _height(rng, o, clearance + 2.0)
    p1, p2 = uniform(rng, 1.5, 2.5), uniform(rng, 1.5, 2.5)  # pillar lengths along the span
    if shape == "bridge":
        length, depth = uniform(rng, 8.0, 14.0), uniform(rng, 4.0, 9.0)
        deck = [(0.0, 0.0), (length, 0.0), (length, depth), (0.0, depth)]
        pillars = [_box(0.0, 0.0, p1, depth), _box(length - p2, 0.0, length, depth)]
    elif shape == "L":  # pillars under the ends of both legs; the corner hangs free
        w, h = uniform(rng, 8.0, 14.0), uniform(rng, 8.0, 14.0)
        a, b = w * uniform(rng, 0.3, 0.5), h * uniform(rng, 0.3, 0.5)
        deck = [(0.0, 0.0), (w, 0.0), (w, b), (a, b), (a, h), (0.0, h)]
        pillars = [_box(w - p1, 0.0, w, b), _box(0.0, h - p2, a, h)]
    else:  # U: pillars under the tips of both arms
        w, h, a1, a2, floor = _you_params(rng, 8.0)
        deck = _you_ring(w, h, a1, a2, floor)
        pillars = [_box(0.0, h - p1, a1, h), _box(w - a2, h - p2, w, h)]
    outline, _ = _centred(deck, (0.0, 0.0))
    dx, dy = outline[0][0] - deck[0][0], outline[0][1] - deck[0][1]
    c = round(clearance, 1)
    parts = [Part(tuple((x + dx, y + dy) for x, y in p), 0.0, c) for p in pillars]
    return Plan(shape, "arch", outline, (*parts, Part(outline, c, top)))


def _box(x0: float, y0: float, x1: float, y1: float) -> Ring:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def over_home_arch(rng: random.Random, o: HardOptions) -> tuple[Plan, Point]:
    """A bridge 5–7 m high and the point under its deck (own frame) where home is."""
    length, depth = uniform(rng, 10.0, 16.0), uniform(rng, 5.0, 9.0)
    p1, p2 = uniform(rng, 1.5, 2.5), uniform(rng, 1.5, 2.5)
    clearance = round(min(uniform(rng, 5.0, 7.0), 0.6 * o.max_height_m), 1)
    top = round(min(max(clearance + uniform(rng, 2.0, 6.0), o.min_height_m), o.max_height_m), 1)
    hx, hy = length / 2.0, depth / 2.0
    home = (uniform(rng, -hx + p1 + 1.5, hx - p2 - 1.5), uniform(rng, -hy + 1.0, hy - 1.0))
    pillars = [_box(-hx, -hy, -hx + p1, hy), _box(hx - p2, -hy, hx, hy)]
    deck = _box(-hx, -hy, hx, hy)
    parts = (*(Part(p, 0.0, clearance) for p in pillars), Part(deck, clearance, top))
    return Plan("bridge", "arch", deck, parts), home


def mapped(plan: Plan, f: Callable[[Point], Point]) -> Plan:
    """The plan with every vertex mapped by ``f`` (rings normalised again)."""
    parts = tuple(
        Part(normalise_ring([f(p) for p in q.ring]), q.base_m, q.top_m) for q in plan.parts
    )
    outline = normalise_ring([f(p) for p in plan.outline])
    if plan.yard is None:
        return Plan(plan.shape, plan.kind, outline, parts)
    return Plan(plan.shape, plan.kind, outline, parts, normalise_ring([f(p) for p in plan.yard]))


def near_copy(rng: random.Random, plan: Plan) -> Plan | None:
    """The plan's outline, one vertex moved by 10–25 % of its size, as one block; None if
    no try gives a well-formed polygon."""
    ring = plan.outline
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    top = max(p.top_m for p in plan.parts)
    for _try in range(50):
        k = _index(rng, len(ring))
        d, phi = size * uniform(rng, 0.10, 0.25), 2.0 * math.pi * rng.random()
        moved = list(ring)
        moved[k] = (ring[k][0] + d * math.cos(phi), ring[k][1] + d * math.sin(phi))
        if well_formed(moved) and signed_area(moved) > 0.5 * signed_area(ring):
            out = normalise_ring(moved)
            if len(out) == len(ring):
                return Plan(plan.shape, "plain", out, (Part(out, 0.0, top),))
    return None


# --------------------------------------------------------------------------- town classes
# Courtyards, copies that differ by a yard or a wing, small targets: only drawn when one of
# HardOptions' town knobs is on (see uavtool.world.hard).

_YARD_DISC_M = 2.0  # a yard cut into a solid roof holds a disc this wide
_WALL_M = 1.2  # and leaves walls at least this thick
_ARM_LEFT_M = 1.5  # a shortened wing keeps at least this much of its length


def yard_parts(outline: Ring, yard: Ring, base_m: float, top_m: float) -> tuple[Part, ...] | None:
    """The walls between ``outline`` and ``yard`` (vertex ``k`` of one answering ``k`` of the
    other) as two blocks, split along two spokes outline[k]–yard[k]: a footprint is a simple
    polygon, so a ring of blocks makes a through-hole. Neighbouring blocks share whole edges
    (no vertex of one lies inside an edge of the other), so rounding opens no gap and no
    overlap. None if no pair of spokes gives two well-formed blocks."""
    n = len(outline)
    if len(yard) != n:
        return None
    for i in range(n):
        j = (i + n // 2) % n
        span_a, span_b = (j - i) % n, (i - j) % n
        a = [outline[(i + k) % n] for k in range(span_a + 1)]
        a += [yard[(j - k) % n] for k in range(span_a + 1)]
        b = [outline[(j + k) % n] for k in range(span_b + 1)]
        b += [yard[(i - k) % n] for k in range(span_b + 1)]
        if all(
            signed_area(p) > 0.0 and len(normalise_ring(p)) == len(p) and well_formed(p)
            for p in (a, b)
        ):
            return Part(tuple(a), base_m, top_m), Part(tuple(b), base_m, top_m)
    return None


def courtyard_plan(rng: random.Random, o: HardOptions) -> Plan:
    """A rectangle or an L of walls 2.2–3.6 m thick around an open yard at least 2.5 m wide
    (2.6–9 m across), one height, as two blocks."""
    for _try in range(20):
        if _index(rng, 2) == 0:
            t = [uniform(rng, 2.2, 3.6) for _ in range(4)]
            w, h = t[3] + uniform(rng, 3.0, 9.0) + t[1], t[0] + uniform(rng, 3.0, 8.0) + t[2]
            shape, ring = "rectangle", [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
        else:  # edges: south, east end, top of the east arm, east of the north arm, north, west
            t = [uniform(rng, 2.2, 3.2) for _ in range(6)]
            a = t[5] + uniform(rng, 2.6, 5.0) + t[3]
            b = t[0] + uniform(rng, 2.6, 5.0) + t[2]
            w, h = a + uniform(rng, 4.0, 9.0), b + uniform(rng, 4.0, 9.0)
            shape, ring = "L", [(0.0, 0.0), (w, 0.0), (w, b), (a, b), (a, h), (0.0, h)]
        top = _height(rng, o)
        outline, _ = _centred(ring, (0.0, 0.0))
        yard = inset_ring(outline, t)
        if yard is None or not well_formed(yard, edge_m=2.5, gap_m=2.5):
            continue
        parts = yard_parts(outline, yard, 0.0, top)
        if parts is not None:
            return Plan(shape, "courtyard", outline, parts, yard)
    raise AssertionError("no courtyard in 20 tries")  # the ranges above always fit


def filled_copy(plan: Plan) -> Plan:
    """The plan's outline as one solid block as tall as the plan."""
    top = max(p.top_m for p in plan.parts)
    return Plan(plan.shape, "plain", plan.outline, (Part(plan.outline, 0.0, top),))


def yard_copy(rng: random.Random, plan: Plan) -> Plan | None:
    """The plan's outline, as tall as the plan, with a yard cut in that holds a 2 m disc and
    leaves walls of 1.2 m or more: for a rectilinear outline a rectangle in its roomiest
    part, else the outline shrunk to 30–60 % about a point it is star-shaped about; None if
    the outline has no room for that."""
    ring = plan.outline
    top = max(p.top_m for p in plan.parts)
    if rectilinear(ring):
        box = _box_yard(rng, ring)
        parts = None if box is None else _split_round(ring, box, top)
        if box is None or parts is None:
            return None
        return Plan(plan.shape, "courtyard", ring, parts, box)
    centre = star_centre(ring)
    if centre is None:
        return None
    cx, cy = centre
    n = len(ring)
    clear = min(point_segment_m(centre, ring[k], ring[(k + 1) % n]) for k in range(n))
    lo = max(0.3, 0.5 * _YARD_DISC_M / clear)
    if lo >= 0.6:
        return None
    for _try in range(8):
        f = uniform(rng, lo, 0.6)
        yard = tuple((cx + f * (x - cx), cy + f * (y - cy)) for x, y in ring)
        wall = min(
            segment_distance_m(ring[i], ring[(i + 1) % n], yard[j], yard[(j + 1) % n])
            for i in range(n)
            for j in range(n)
        )
        if wall >= _WALL_M and well_formed(yard):
            parts = yard_parts(ring, yard, 0.0, top)
            if parts is not None:
                return Plan(plan.shape, "courtyard", ring, parts, yard)
    return None


def _box_yard(rng: random.Random, ring: Ring, steps: int = 16) -> Ring | None:
    """A rectangular yard (sides parallel to the rectilinear ring's) about the grid point
    farthest from the edges in the chessboard metric: its sides 2 m or more, its walls
    1.2 m or more; None if the ring has no room."""
    n = len(ring)
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    best, best_m = (0.0, 0.0), 0.0
    for i in range(1, steps):
        for j in range(1, steps):
            c = (
                min(xs) + (max(xs) - min(xs)) * i / steps,
                min(ys) + (max(ys) - min(ys)) * j / steps,
            )
            if inside(c, ring):
                clear = min(_chessboard_m(c, ring[k], ring[(k + 1) % n]) for k in range(n))
                if clear > best_m:
                    best, best_m = c, clear
    room = best_m - _WALL_M
    if room < 0.5 * _YARD_DISC_M:
        return None
    hx = uniform(rng, max(0.5 * _YARD_DISC_M, 0.6 * room), room)
    hy = uniform(rng, max(0.5 * _YARD_DISC_M, 0.6 * room), room)
    return _box(best[0] - hx, best[1] - hy, best[0] + hx, best[1] + hy)


def _chessboard_m(c: Point, a: Point, b: Point) -> float:
    """Chessboard (L∞) distance from ``c`` to an axis-aligned segment ``a``–``b``."""
    qx = min(max(c[0], min(a[0], b[0])), max(a[0], b[0]))
    qy = min(max(c[1], min(a[1], b[1])), max(a[1], b[1]))
    return max(abs(c[0] - qx), abs(c[1] - qy))


def _split_round(outline: Ring, yard: Ring, top_m: float) -> tuple[Part, ...] | None:
    """The walls between ``outline`` and a ``yard`` inside it as two blocks, split along two
    spokes from opposite corners of the yard to vertices of the outline (shortest first);
    None if no such pair gives two well-formed blocks that tile the walls."""
    n, m = len(outline), len(yard)
    walls = signed_area(outline) - signed_area(yard)
    for a in range(m // 2):
        b = a + m // 2
        near_a = sorted(range(n), key=lambda i: math.dist(outline[i], yard[a]))
        near_b = sorted(range(n), key=lambda j: math.dist(outline[j], yard[b]))
        for i in near_a:
            for j in near_b:
                if i == j:
                    continue
                span, back = (j - i) % n, (b - a) % m
                one = [outline[(i + k) % n] for k in range(span + 1)]
                one += [yard[(b - k) % m] for k in range(back + 1)]
                two = [outline[(j + k) % n] for k in range(n - span + 1)]
                two += [yard[(a - k) % m] for k in range(m - back + 1)]
                pieces = (one, two)
                if (
                    all(signed_area(p) > 0.0 and well_formed(p) for p in pieces)
                    and abs(signed_area(one) + signed_area(two) - walls) < 1e-6 * walls
                    and all(len(normalise_ring(p)) == len(p) for p in pieces)
                ):
                    return Part(tuple(one), 0.0, top_m), Part(tuple(two), 0.0, top_m)
    return None


def wing_copy(rng: random.Random, plan: Plan) -> Plan | None:
    """The plan with one wing (an edge with two convex corners, as an arm's end) moved in by
    2–4 m, keeping at least 1.5 m of it, or (an arm that meets the body at a reflex corner,
    about a third of the time) the arm taken off; as tall as the plan, one block, or a
    courtyard's two blocks with the same walls (only shortened). None for a plan whose
    outline is not rectilinear (the radial shapes) or with no wing that allows either."""
    ring = plan.outline
    n = len(ring)
    if not rectilinear(ring):
        return None
    convex = convex_corners(ring)
    wings: list[tuple[int, float, bool]] = []  # tip edge, its arm's length, can come off
    for k in range(n):
        k1 = (k + 1) % n
        if not (convex[k] and convex[k1]):
            continue
        back, ahead = math.dist(ring[k - 1], ring[k]), math.dist(ring[k1], ring[(k + 2) % n])
        # an arm comes off where its shorter side ends in a reflex corner (the body's)
        if back < ahead:
            off = not convex[k - 1]
        elif ahead < back:
            off = not convex[(k + 2) % n]
        else:
            off = not convex[k - 1] and not convex[(k + 2) % n]
        off = off and plan.yard is None
        arm = min(back, ahead)
        if arm - 2.0 >= _ARM_LEFT_M or off:
            wings.append((k, arm, off))
    if not wings:
        return None
    first, f, g = _index(rng, len(wings)), rng.random(), rng.random()
    top = max(p.top_m for p in plan.parts)
    for step in range(len(wings)):
        k, arm, off = wings[(first + step) % len(wings)]
        shorten = arm - 2.0 >= _ARM_LEFT_M
        remove = off and (not shorten or g < 0.35)
        by_m = 2.0 + f * (min(4.0, arm - _ARM_LEFT_M) - 2.0)
        out = normalise_ring(moved_wing(ring, k, by_m, remove=remove))
        if not well_formed(out) or signed_area(out) >= signed_area(ring) - 0.5:
            continue
        if plan.yard is None:
            return Plan(plan.shape, "plain", out, (Part(out, 0.0, top),))
        yard = normalise_ring(moved_wing(plan.yard, k, by_m, remove=False))
        if len(out) == n and len(yard) == n and well_formed(yard, edge_m=2.5, gap_m=2.5):
            parts = yard_parts(out, yard, 0.0, top)
            if parts is not None:
                return Plan(plan.shape, "courtyard", out, parts, yard)
    return None


def moved_wing(ring: Ring, k: int, by_m: float, *, remove: bool) -> list[Point]:
    """``ring`` with edge k–k+1 moved ``by_m`` back along its neighbouring edges (both run
    along one axis), or (``remove``) back to where the shorter of them ends: that coordinate
    exactly, so the repeated and straight vertices left are dropped by normalise_ring."""
    n = len(ring)
    a, b, back, ahead = ring[k], ring[(k + 1) % n], ring[k - 1], ring[(k + 2) % n]
    axis = 0 if abs(back[0] - a[0]) > abs(back[1] - a[1]) else 1
    if remove:
        value = (back if math.dist(back, a) <= math.dist(b, ahead) else ahead)[axis]
    else:
        value = a[axis] + (by_m if back[axis] > a[axis] else -by_m)
    out = list(ring)
    for i in (k, (k + 1) % n):
        out[i] = (value, out[i][1]) if axis == 0 else (out[i][0], value)
    return out


def small_plan(rng: random.Random, o: HardOptions) -> Plan:
    """One block of a :data:`SHAPES` footprint scaled to 3.05–4.95 m across (its farthest
    two vertices), arms still 1.2 m or wider; a rectangle if 30 tries find none."""
    for _try in range(30):
        shape = SHAPES[_index(rng, len(SHAPES))]
        ring, _ = _MAKERS[shape](rng)
        across = uniform(rng, 3.05, 4.95)
        size = max(math.dist(p, q) for p in ring for q in ring)
        small = tuple((across / size * x, across / size * y) for x, y in ring)
        if well_formed(small, gap_m=1.2):
            return Plan(shape, "plain", small, (Part(small, 0.0, _height(rng, o)),))
    w = uniform(rng, 2.0, 3.5)
    ring = _box(-w / 2.0, -1.0, w / 2.0, 1.0)
    return Plan("rectangle", "plain", ring, (Part(ring, 0.0, _height(rng, o)),))
