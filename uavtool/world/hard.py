"""Seeded HARD scenes: decoys of the target, stepped towers, arches, tall and spread out.

From one seed, :func:`generate_hard_scene_with_info` draws 5–8 buildings 3–25 m tall over a
square wider than one nadir photo from 45 m (a 60° camera there sees about ±26 × ±19.5 m)
and makes the target hard to pick:

* a **mirror** image of the target in a close hue (10–20° away): only a matcher that
  rejects reflections tells them apart (the target's outline is always chiral then);
* a **scaled** copy (0.6–1.5×, turned) in a clearly different hue;
* a **near**-identical copy: the target's outline with one vertex moved by 10–25 % of its
  size, in the next hue over;
* **stepped** towers (two or three stacked blocks of shrinking footprint, one colour) and
  **arches** (two pillars and a block resting on both: a tunnel you see through from the
  side); the target is sometimes either;
* a building 1–3 m from home, and optionally an arch over home (home under a block 5–7 m up).

Every building is turned by a random angle; footprints stay ``margin_m`` apart, so nothing
stands over the target. :class:`HardSceneInfo` names the decoys by kind, so a benchmark
can count mirror matches apart from other wrong matches.

Determinism as in :mod:`uavtool.world.generator`: only ``random.Random(seed).random()``
and ``math`` feed the result (shuffles and choices are written out here), coordinates are
rounded to centimetres and heights to decimetres, so a seed gives the same scene everywhere.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields

from uavtool.geo import GeoPoint
from uavtool.world.errors import SceneError
from uavtool.world.generator import _hsv_rgb, _index
from uavtool.world.polygon import normalise_ring, signed_area
from uavtool.world.scene import Block, Building, Scene, scene_from_dict, scene_to_dict

MAX_HARD_BUILDINGS = 16  # hue slots stay >= 22.5° apart, so the mirror decoy's hue is nearest
HOME = GeoPoint(50.0647, 19.945, 219.0)  # the paper scene's home

_HOME_CLEAR_M = 4.0  # buildings not deliberately beside or over home keep this far from it
_ROUND_SLACK_M = 0.02  # centimetre rounding moves a footprint by up to ~1.5 cm

Point = tuple[float, float]
Ring = tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class HardOptions:
    """Knobs of :func:`generate_hard_scene`; raises SceneError on construction if one is out of
    range. Probabilities are in [0, 1]; each is drawn once per scene unless said otherwise."""

    min_buildings: int = 5  # total count (decoys included), drawn uniformly in [min, max]
    max_buildings: int = 8
    min_height_m: float = 3.0  # every building's roof top is within [min, max]
    max_height_m: float = 25.0
    spread_m: float = 35.0  # half-side of the square around home the buildings stand in
    margin_m: float = 4.0  # least gap between two buildings' footprints
    stepped_p: float = 0.3  # per building (target included): two or three stacked tiers
    arch_p: float = 0.15  # per building other than the target and its decoys: an arch
    target_arch_p: float = 0.25  # the target is an arch (its model must keep the tunnel)
    mirror_decoy_p: float = 0.6  # a mirror image of the target in a close hue
    scaled_decoy_p: float = 0.5  # a scaled, turned copy of the target in another hue
    near_decoy_p: float = 0.5  # the target's outline with one vertex moved
    home_beside_p: float = 0.3  # one building's footprint 1–3 m from home
    home_overhang_p: float = 0.0  # an arch over home; wins over home_beside_p

    def __post_init__(self) -> None:
        if not 1 <= self.min_buildings <= self.max_buildings <= MAX_HARD_BUILDINGS:
            raise SceneError(
                f"buildings must satisfy 1 <= min <= max <= {MAX_HARD_BUILDINGS}, got "
                f"{self.min_buildings}..{self.max_buildings}"
            )
        if not 1.0 <= self.min_height_m <= self.max_height_m <= 200.0:
            raise SceneError(
                "heights must satisfy 1 <= min <= max <= 200 m, got "
                f"{self.min_height_m}..{self.max_height_m}"
            )
        if not 5.0 <= self.spread_m <= 1000.0:
            raise SceneError(f"spread must be 5..1000 m, got {self.spread_m}")
        if not 0.0 <= self.margin_m <= 50.0:
            raise SceneError(f"margin must be 0..50 m, got {self.margin_m}")
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name.endswith("_p") and not 0.0 <= value <= 1.0:
                raise SceneError(f"{f.name} is a probability in [0, 1], got {value}")


@dataclass(frozen=True, slots=True)
class HardSceneInfo:
    """What makes a generated scene hard, by building name (None: not in this scene)."""

    target: str
    target_shape: str  # "L", "T", "U", "cross", "rectangle", "convex", "concave" or "bridge"
    target_kind: str  # "plain", "stepped" or "arch"
    mirror_decoy: str | None  # mirror image of the target, hue 10–20° away
    scaled_decoy: str | None  # target scaled 0.6–1.5×, another hue
    near_decoy: str | None  # target's outline with one vertex moved 10–25 % of its size
    stepped: tuple[str, ...]  # buildings of stacked, shrinking tiers
    arches: tuple[str, ...]  # buildings with a tunnel (a raised block resting on pillars)
    beside_home: str | None  # footprint 1–3 m from home
    over_home: str | None  # an arch whose raised block is over home

    @property
    def decoys(self) -> tuple[str, ...]:
        """Names of all decoys of the target."""
        found = (self.mirror_decoy, self.scaled_decoy, self.near_decoy)
        return tuple(n for n in found if n is not None)

    def summary(self) -> str:
        """One line, e.g. ``target b03 (stepped L); mirror decoy b05; arches b01``."""
        kind = "" if self.target_kind == "plain" else f"{self.target_kind} "
        out = [f"target {self.target} ({kind}{self.target_shape})"]
        for label, name in (
            ("mirror decoy", self.mirror_decoy),
            ("near decoy", self.near_decoy),
            ("scaled decoy", self.scaled_decoy),
            ("home beside", self.beside_home),
            ("arch over home", self.over_home),
        ):
            if name is not None:
                out.append(f"{label} {name}")
        if self.stepped:
            out.append(f"stepped {' '.join(self.stepped)}")
        if self.arches:
            out.append(f"arches {' '.join(self.arches)}")
        return "; ".join(out)


def generate_hard_scene(*, seed: int, options: HardOptions = HardOptions()) -> Scene:
    """A hard scene for ``seed`` (see the module doc); the scene of
    :func:`generate_hard_scene_with_info`."""
    return generate_hard_scene_with_info(seed=seed, options=options)[0]


# --------------------------------------------------------------------------- plans


@dataclass(frozen=True, slots=True)
class _Part:
    ring: Ring
    base_m: float
    top_m: float


@dataclass(frozen=True, slots=True)
class _Plan:
    """A building in its own frame (origin near its middle) before it is turned and placed."""

    shape: str
    kind: str
    outline: Ring  # seen from above: every part's footprint lies inside it
    parts: tuple[_Part, ...]


def _u(rng: random.Random, lo: float, hi: float) -> float:
    return lo + (hi - lo) * rng.random()


def _centred(ring: Sequence[Point], kernel: Point) -> tuple[Ring, Point]:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return tuple((x - cx, y - cy) for x, y in ring), (kernel[0] - cx, kernel[1] - cy)


# Each maker returns a counter-clockwise ring and a point it is star-shaped about (shrinking
# the ring towards that point keeps it inside: how stepped tiers are made). The U has none.
def _rectangle(rng: random.Random) -> tuple[Ring, Point]:
    w, h = _u(rng, 4.0, 12.0), _u(rng, 4.0, 12.0)
    return _centred([(0, 0), (w, 0), (w, h), (0, h)], (w / 2.0, h / 2.0))


def _ell(rng: random.Random) -> tuple[Ring, Point]:
    w, h = _u(rng, 6.0, 13.0), _u(rng, 6.0, 13.0)
    a, b = w * _u(rng, 0.3, 0.6), h * _u(rng, 0.3, 0.6)
    return _centred([(0, 0), (w, 0), (w, b), (a, b), (a, h), (0, h)], (a / 2.0, b / 2.0))


def _tee(rng: random.Random) -> tuple[Ring, Point]:
    w, h = _u(rng, 6.0, 13.0), _u(rng, 6.0, 13.0)
    stem, bar = w * _u(rng, 0.25, 0.45), h * _u(rng, 0.25, 0.45)
    x0 = (w - stem) * _u(rng, 0.15, 0.85)  # the stem off-centre: no mirror symmetry
    x1 = x0 + stem
    ring = [(x0, 0), (x1, 0), (x1, h - bar), (w, h - bar), (w, h), (0, h), (0, h - bar)]
    return _centred([*ring, (x0, h - bar)], ((x0 + x1) / 2.0, h - bar / 2.0))


def _you_params(rng: random.Random, lo: float) -> tuple[float, float, float, float, float]:
    w, h = _u(rng, lo, 13.0), _u(rng, lo, 13.0)
    return w, h, w * _u(rng, 0.18, 0.32), w * _u(rng, 0.18, 0.32), h * _u(rng, 0.25, 0.45)


def _you_ring(w: float, h: float, a1: float, a2: float, floor: float) -> list[Point]:
    return [(0, 0), (w, 0), (w, h), (w - a2, h), (w - a2, floor), (a1, floor), (a1, h), (0, h)]


def _you(rng: random.Random) -> tuple[Ring, Point]:
    w, h, a1, a2, floor = _you_params(rng, 6.0)
    return _centred(_you_ring(w, h, a1, a2, floor), (w / 2.0, floor / 2.0))


def _cross(rng: random.Random) -> tuple[Ring, Point]:
    w, h = _u(rng, 6.0, 13.0), _u(rng, 6.0, 13.0)
    a, b = w * _u(rng, 0.12, 0.25), h * _u(rng, 0.12, 0.25)  # half-widths of the two bars
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
    r = _u(rng, 2.5, 6.5)
    step = 2.0 * math.pi / n
    angles = [k * step + 0.5 * step * rng.random() for k in range(n)]  # increasing: simple
    # a star alternates outer and inner radii; a convex ring keeps to one circle (its gaps
    # are all under 180°)
    radii = [r if k % 2 == 0 or not concave else r * _u(rng, 0.45, 0.7) for k in range(n)]
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
_SHAPES = tuple(_MAKERS)
_ARCHES = ("bridge", "L", "U")


def _height(rng: random.Random, o: HardOptions, lo_m: float = 0.0) -> float:
    lo = min(max(o.min_height_m, lo_m), o.max_height_m)
    return round(_u(rng, lo, o.max_height_m), 1)


def _plain_or_stepped(rng: random.Random, o: HardOptions, shape: str) -> _Plan:
    ring, kernel = _MAKERS[shape](rng)
    if shape == "U" or rng.random() >= o.stepped_p:
        return _Plan(shape, "plain", ring, (_Part(ring, 0.0, _height(rng, o)),))
    top = _height(rng, o, 6.0)
    if rng.random() < 0.4:  # three tiers
        t1 = top * _u(rng, 0.3, 0.5)
        tops = [t1, t1 + (top - t1) * _u(rng, 0.4, 0.7), top]
        f1 = _u(rng, 0.5, 0.8)
        scales = [1.0, f1, f1 * _u(rng, 0.55, 0.8)]
    else:
        tops, scales = [top * _u(rng, 0.4, 0.7), top], [1.0, _u(rng, 0.5, 0.8)]
    kx, ky = kernel
    parts, base = [], 0.0
    for t, f in zip(tops, scales, strict=True):
        tier = tuple((kx + f * (x - kx), ky + f * (y - ky)) for x, y in ring)
        parts.append(_Part(tier, base, round(t, 1)))
        base = round(t, 1)
    return _Plan(shape, "stepped", ring, tuple(parts))


def _arch(rng: random.Random, o: HardOptions, shape: str) -> _Plan:
    """Two pillars (base 0 up to the clearance) and a block resting on both (up to the top)."""
    clearance = _u(rng, 2.5, 4.5)
    if max(o.min_height_m, clearance + 2.0) > o.max_height_m:  # too low for a 2 m deck
        clearance = 0.5 * o.max_height_m
    top = _height(rng, o, clearance + 2.0)
    p1, p2 = _u(rng, 1.5, 2.5), _u(rng, 1.5, 2.5)  # pillar lengths along the span
    if shape == "bridge":
        length, depth = _u(rng, 8.0, 14.0), _u(rng, 4.0, 9.0)
        deck = [(0.0, 0.0), (length, 0.0), (length, depth), (0.0, depth)]
        pillars = [_box(0.0, 0.0, p1, depth), _box(length - p2, 0.0, length, depth)]
    elif shape == "L":  # pillars under the ends of both legs; the corner hangs free
        w, h = _u(rng, 8.0, 14.0), _u(rng, 8.0, 14.0)
        a, b = w * _u(rng, 0.3, 0.5), h * _u(rng, 0.3, 0.5)
        deck = [(0.0, 0.0), (w, 0.0), (w, b), (a, b), (a, h), (0.0, h)]
        pillars = [_box(w - p1, 0.0, w, b), _box(0.0, h - p2, a, h)]
    else:  # U: pillars under the tips of both arms
        w, h, a1, a2, floor = _you_params(rng, 8.0)
        deck = _you_ring(w, h, a1, a2, floor)
        pillars = [_box(0.0, h - p1, a1, h), _box(w - a2, h - p2, w, h)]
    outline, _ = _centred(deck, (0.0, 0.0))
    dx, dy = outline[0][0] - deck[0][0], outline[0][1] - deck[0][1]
    c = round(clearance, 1)
    parts = [_Part(tuple((x + dx, y + dy) for x, y in p), 0.0, c) for p in pillars]
    return _Plan(shape, "arch", outline, (*parts, _Part(outline, c, top)))


def _box(x0: float, y0: float, x1: float, y1: float) -> Ring:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def _over_home_arch(rng: random.Random, o: HardOptions) -> tuple[_Plan, Point]:
    """A bridge 5–7 m high and the point under its deck (own frame) where home is."""
    length, depth = _u(rng, 10.0, 16.0), _u(rng, 5.0, 9.0)
    p1, p2 = _u(rng, 1.5, 2.5), _u(rng, 1.5, 2.5)
    clearance = round(min(_u(rng, 5.0, 7.0), 0.6 * o.max_height_m), 1)
    top = round(min(max(clearance + _u(rng, 2.0, 6.0), o.min_height_m), o.max_height_m), 1)
    hx, hy = length / 2.0, depth / 2.0
    home = (_u(rng, -hx + p1 + 1.5, hx - p2 - 1.5), _u(rng, -hy + 1.0, hy - 1.0))
    pillars = [_box(-hx, -hy, -hx + p1, hy), _box(hx - p2, -hy, hx, hy)]
    deck = _box(-hx, -hy, hx, hy)
    parts = (*(_Part(p, 0.0, clearance) for p in pillars), _Part(deck, clearance, top))
    return _Plan("bridge", "arch", deck, parts), home


def _mapped(plan: _Plan, f: Callable[[Point], Point]) -> _Plan:
    parts = tuple(
        _Part(normalise_ring([f(p) for p in q.ring]), q.base_m, q.top_m) for q in plan.parts
    )
    return _Plan(plan.shape, plan.kind, normalise_ring([f(p) for p in plan.outline]), parts)


def _near_copy(rng: random.Random, plan: _Plan) -> _Plan | None:
    """The plan's outline, one vertex moved by 10–25 % of its size, as one block; None if
    no try gives a well-formed polygon."""
    ring = plan.outline
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    top = max(p.top_m for p in plan.parts)
    for _try in range(50):
        k = _index(rng, len(ring))
        d, phi = size * _u(rng, 0.10, 0.25), 2.0 * math.pi * rng.random()
        moved = list(ring)
        moved[k] = (ring[k][0] + d * math.cos(phi), ring[k][1] + d * math.sin(phi))
        if _well_formed(moved) and signed_area(moved) > 0.5 * signed_area(ring):
            out = normalise_ring(moved)
            if len(out) == len(ring):
                return _Plan(plan.shape, "plain", out, (_Part(out, 0.0, top),))
    return None


# --------------------------------------------------------------------------- geometry


def _cross3(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _point_segment_m(p: Point, a: Point, b: Point) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)


def _well_formed(ring: Sequence[Point], *, edge_m: float = 0.5, gap_m: float = 0.3) -> bool:
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
                _point_segment_m(a, c, d),
                _point_segment_m(b, c, d),
                _point_segment_m(c, a, b),
                _point_segment_m(d, a, b),
            )
            if near < gap_m:
                return False
    return True


def _inside(p: Point, ring: Sequence[Point]) -> bool:
    inside = False
    n = len(ring)
    for i in range(n):
        (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % n]
        if (y0 > p[1]) != (y1 > p[1]) and p[0] < x0 + (p[1] - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def _chiral(ring: Ring) -> bool:
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
            turn = _rotation(_heading(b[j], b[(j + 1) % len(b)]) - ha)
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
        worst = max(worst, min(_point_segment_m(p, b[k], b[(k + 1) % n]) for k in range(n)))
        if worst >= stop_m:
            return stop_m
    return worst


def _beside_home(rng: random.Random, ring: Ring) -> Point | None:
    """Where home is, in the (turned) ring's frame, 1.1–2.9 m outside it; None if no try
    finds a spot whose nearest edge is that one (inside a U's notch, say)."""
    n = len(ring)
    for _try in range(20):
        k = _index(rng, n)
        a, b = ring[k], ring[(k + 1) % n]
        length = math.dist(a, b)
        nx, ny = (b[1] - a[1]) / length, (a[0] - b[0]) / length  # outward: ring is CCW
        t, gap = _u(rng, 0.25, 0.75), _u(rng, 1.1, 2.9)
        p = (a[0] + t * (b[0] - a[0]) + gap * nx, a[1] + t * (b[1] - a[1]) + gap * ny)
        nearest = min(_point_segment_m(p, ring[i], ring[(i + 1) % n]) for i in range(n))
        if 1.1 <= nearest <= 2.9 and not _inside(p, ring):
            return p
    return None


# --------------------------------------------------------------------------- the scene


def generate_hard_scene_with_info(
    *, seed: int, options: HardOptions = HardOptions()
) -> tuple[Scene, HardSceneInfo]:
    """A hard scene for ``seed`` and what makes it hard.

    The count is drawn in ``[min_buildings, max_buildings]``; decoys take places in that
    count (mirror first, then near, then scaled) and are left out when there is no room.
    Building centres are drawn in a square of half-side ``spread_m`` around home (it grows
    slowly if crowded); names ``b00``… are in a seeded order, so the target's name says
    nothing. The description holds the command that makes the scene again. Raises
    SceneError only if the result fails the scene-file validation (a bug).
    """
    o = options
    rng = random.Random(seed)
    n = o.min_buildings + _index(rng, o.max_buildings - o.min_buildings + 1)
    hue0 = 360.0 * rng.random()
    target_arch = rng.random() < o.target_arch_p
    want_mirror = rng.random() < o.mirror_decoy_p
    want_near = rng.random() < o.near_decoy_p
    want_scaled = rng.random() < o.scaled_decoy_p
    over_home = rng.random() < o.home_overhang_p and n >= 2
    beside = not over_home and rng.random() < o.home_beside_p

    # a mirror decoy of a symmetric target would be a plain copy: only chiral targets get one
    target, want_mirror = _target_plan(rng, o, arch=target_arch, chiral=want_mirror)
    roles: list[tuple[str, _Plan]] = [("target", target)]
    home_local: Point = (0.0, 0.0)
    if over_home:
        arch, home_local = _over_home_arch(rng, o)
        roles.append(("over_home", arch))
    if want_mirror and len(roles) < n:
        roles.append(("mirror", _mapped(target, lambda p: (-p[0], p[1]))))
    if want_near and len(roles) < n:
        near = _near_copy(rng, target)
        if near is not None:
            roles.append(("near", near))
    if want_scaled and len(roles) < n:
        s = _u(rng, 0.6, 1.5)
        roles.append(("scaled", _mapped(target, lambda p: (s * p[0], s * p[1]))))
    while len(roles) < n:
        if rng.random() < o.arch_p:
            plan = _arch(rng, o, _ARCHES[_index(rng, len(_ARCHES))])
        else:
            plan = _plain_or_stepped(rng, o, _SHAPES[_index(rng, len(_SHAPES))])
        roles.append(("other", plan))

    hues = _hues(rng, [r for r, _ in roles], hue0)
    angles = [2.0 * math.pi * rng.random() for _ in roles]
    turned = [_mapped(plan, _rotation(a)) for (_, plan), a in zip(roles, angles, strict=True)]
    centres: list[Point | None] = [None] * n
    if over_home:
        hx, hy = _rotation(angles[1])(home_local)
        centres[1] = (-hx, -hy)
    beside_index = None
    if beside:
        k = _index(rng, n)
        spot = _beside_home(rng, turned[k].outline)
        if spot is not None:
            centres[k], beside_index = (-spot[0], -spot[1]), k
    _place(rng, o, turned, centres)

    order = _permutation(rng, n)  # order[position] = role index
    name_of = {i: f"b{pos:02d}" for pos, i in enumerate(order)}
    buildings = tuple(_building(name_of[i], hues[i], turned[i], centres[i]) for i in order)

    def named(role: str) -> str | None:
        return next((name_of[i] for i, (r, _) in enumerate(roles) if r == role), None)

    info = HardSceneInfo(
        target=name_of[0],
        target_shape=target.shape,
        target_kind=target.kind,
        mirror_decoy=named("mirror"),
        scaled_decoy=named("scaled"),
        near_decoy=named("near"),
        stepped=tuple(sorted(name_of[i] for i, p in enumerate(turned) if p.kind == "stepped")),
        arches=tuple(sorted(name_of[i] for i, p in enumerate(turned) if p.kind == "arch")),
        beside_home=None if beside_index is None else name_of[beside_index],
        over_home=named("over_home"),
    )
    scene = Scene(
        name=f"hard-{seed}",
        home=HOME,
        home_heading_deg=0.0,
        buildings=buildings,
        target=info.target,
        description=f"{hard_command(seed, o)}: {info.summary()}",
    )
    # what we write must load: run the file validation on it
    return scene_from_dict(scene_to_dict(scene), source=scene.name), info


def _target_plan(
    rng: random.Random, o: HardOptions, *, arch: bool, chiral: bool
) -> tuple[_Plan, bool]:
    """The target's plan, and whether it is chiral (tried up to 100 times if ``chiral``)."""
    tries = 0
    while True:
        tries += 1
        if arch:
            plan = _arch(rng, o, _ARCHES[_index(rng, len(_ARCHES))])
        else:
            plan = _plain_or_stepped(rng, o, _SHAPES[_index(rng, len(_SHAPES))])
        if not chiral:
            return plan, False
        if _chiral(plan.outline) or tries == 100:
            return plan, _chiral(plan.outline)


def _hues(rng: random.Random, roles: Sequence[str], hue0: float) -> list[float]:
    """Hue per role, degrees: evenly spaced slots; the near decoy next to the target, the
    scaled one opposite, the mirror decoy 10–20° off the target (closer than any slot)."""
    slots = len(roles) - (1 if "mirror" in roles else 0)
    spacing = 360.0 / slots
    free = list(range(1, slots))
    slot_of: dict[int, int] = {}
    for i, role in enumerate(roles):
        if role == "target":
            slot_of[i] = 0
        elif role == "near":
            slot_of[i] = free.pop(0)
    for i, role in enumerate(roles):
        if role == "scaled":
            best = max(free, key=lambda j: min(j, slots - j))
            free.remove(best)
            slot_of[i] = best
    for i, role in enumerate(roles):
        if i not in slot_of and role != "mirror":
            slot_of[i] = free.pop(0)
    out = []
    for i, role in enumerate(roles):
        if role == "mirror":
            off = 10.0 + (min(20.0, 0.45 * spacing) - 10.0) * rng.random()
            out.append((hue0 + (off if rng.random() < 0.5 else -off)) % 360.0)
        else:
            out.append((hue0 + slot_of[i] * spacing) % 360.0)
    return out


def _rotation(angle: float) -> Callable[[Point], Point]:
    c, s = math.cos(angle), math.sin(angle)
    return lambda p: (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _place(
    rng: random.Random, o: HardOptions, plans: Sequence[_Plan], centres: list[Point | None]
) -> None:
    """Fill the missing centres: drawn in the square, bounding circles ``margin_m`` apart
    and ``_HOME_CLEAR_M`` from home; the square grows slowly when crowded."""
    radius = [max(math.hypot(x, y) for x, y in p.outline) for p in plans]
    placed = [(c[0], c[1], radius[i]) for i, c in enumerate(centres) if c is not None]
    half = o.spread_m
    gap = o.margin_m + _ROUND_SLACK_M
    for i, c in enumerate(centres):
        if c is not None:
            continue
        r = radius[i]
        while True:
            ex, ny = (2.0 * rng.random() - 1.0) * half, (2.0 * rng.random() - 1.0) * half
            if math.hypot(ex, ny) >= r + _HOME_CLEAR_M and all(
                math.hypot(ex - px, ny - py) >= r + pr + gap for px, py, pr in placed
            ):
                break
            half *= 1.001
        placed.append((ex, ny, r))
        centres[i] = (ex, ny)


def _permutation(rng: random.Random, n: int) -> list[int]:
    out = list(range(n))
    for i in range(n - 1, 0, -1):  # Fisher–Yates, written out: random.shuffle may change
        j = _index(rng, i + 1)
        out[i], out[j] = out[j], out[i]
    return out


def _building(name: str, hue: float, plan: _Plan, centre: Point | None) -> Building:
    ex, ny = centre if centre is not None else (0.0, 0.0)

    def at(p: Point) -> Point:
        return (round(ex + p[0], 2) + 0.0, round(ny + p[1], 2) + 0.0)  # + 0.0: no -0.0

    blocks = tuple(
        Block(normalise_ring([at(p) for p in part.ring]), part.base_m, part.top_m)
        for part in plan.parts
    )
    return Building(name, _hsv_rgb(hue, 0.75, 0.85), blocks)


def hard_command(seed: int, options: HardOptions = HardOptions()) -> str:
    """The ``uavtool scene random --hard`` command line that makes this scene; options the
    command has no flag for are listed after it."""
    default = HardOptions()
    words = ["uavtool scene random --hard", f"--seed {seed}"]
    rest: list[str] = []
    counts = (options.min_buildings, options.max_buildings)
    if counts != (default.min_buildings, default.max_buildings):
        if counts[0] == counts[1]:
            words.append(f"--buildings {counts[0]}")
        else:
            rest += [f"min_buildings={counts[0]}", f"max_buildings={counts[1]}"]
    flags = {"margin_m": "--margin", "spread_m": "--spread"}
    for f in fields(options):
        value, was = getattr(options, f.name), getattr(default, f.name)
        if f.name in ("min_buildings", "max_buildings") or value == was:
            continue
        if f.name in flags:
            words.append(f"{flags[f.name]} {value:g}")
        elif f.name == "home_overhang_p" and value == 1.0:
            words.append("--overhang")
        else:
            rest.append(f"{f.name}={value:g}")
    line = " ".join(words)
    return f"{line} (HardOptions: {', '.join(rest)})" if rest else line
