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
from uavtool.world.hard_geometry import Point, Ring, well_formed
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
    return Plan(plan.shape, plan.kind, normalise_ring([f(p) for p in plan.outline]), parts)


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
