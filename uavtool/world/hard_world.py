"""The world classes of hard scenes (issue 45): any light, any ground, ground areas, a ground
texture, and near-shape decoys of the target.

:func:`draw_world` runs after everything else of :func:`uavtool.world.hard.generate_hard_scene`
(home included) and draws only for the knobs that are on, so the buildings and home are the
seed's own and a scene with the knobs off is what it always was. Like the rest of the
generator, only ``rng.random()`` and ``math`` feed it, and coordinates are rounded to
centimetres.

* **light**: the sun 5–90° above the horizon from any azimuth, ambient 0.15–0.8;
* **ground colour**: grass greens, earth browns or any colour at all, its hue at least the
  vectorizer's hue tolerance (``VectorizeParams.hue_tolerance_deg``) from the target's (a
  ground of the target's colour is another problem) and every channel of it or of some
  building 40 levels apart (no roof the ground's own colour);
* **ground areas**: 2–6 lawns, roads, car parks and fields around home, in colours kept as
  the ground's; they may pass under buildings (buildings stand over them);
* **texture**: seeded grain (0.15–0.5 m cells) or smooth noise (1–4 m patches), 4–14 DN;
* **near shapes**: one or two buildings of the target's exact colour and height whose
  outline is almost the target's: the aspect 5–10 % off, a trapezoid whose top is 60–95 % of
  its base (a rectangular target), a corner chamfered or notched by 15–30 % of its shorter
  edge, or an arm 15 % shorter (an L, T, U or cross).
"""

from __future__ import annotations

import colorsys
import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from uavtool.world.generator import _hsv_rgb, _index
from uavtool.world.ground import GroundArea, GroundTexture, TextureKind
from uavtool.world.hard_geometry import (
    Point,
    Ring,
    convex_corners,
    inside,
    rectilinear,
    ring_distance_m,
    rotation,
    well_formed,
)
from uavtool.world.hard_shapes import Plan, moved_wing, uniform
from uavtool.world.polygon import normalise_ring
from uavtool.world.scene import RGB, Block, Building, Lighting

if TYPE_CHECKING:
    from uavtool.world.hard import HardOptions

NEAR_CLASSES = ("aspect", "trapezoid", "chamfer", "notch", "arm")
_CONTRAST_DN = 40  # the ground and a roof differ by this much in some channel
_HOME_CLEAR_M = 4.0
_AREA_KINDS = ("lawn", "road", "car park", "field")


@dataclass(frozen=True, slots=True)
class World:
    """What :func:`draw_world` drew; None or empty where its knob is off."""

    lighting: Lighting | None = None
    ground_rgb: RGB | None = None
    areas: tuple[GroundArea, ...] = ()
    texture: GroundTexture | None = None
    near_shapes: tuple[Building, ...] = ()
    near_classes: tuple[str, ...] = ()  # the class of each near shape

    def labels(self) -> tuple[str, ...]:
        """Short phrases for the scene's description, e.g. ``sun 12° from 250°``."""
        out = []
        if self.lighting is not None:
            light = self.lighting
            out.append(
                f"sun {light.sun_elevation_deg:g}° up from {light.sun_azimuth_deg:g}°, "
                f"ambient {light.ambient:g}"
            )
        if self.ground_rgb is not None:
            out.append("ground " + ",".join(str(c) for c in self.ground_rgb))
        if self.areas:
            out.append("areas " + " ".join(a.name for a in self.areas))
        if self.texture is not None:
            t = self.texture
            out.append(f"{t.kind.value} texture {t.amplitude_dn:g} DN over {t.scale_m:g} m")
        return tuple(out)


def draw_world(
    rng: random.Random,
    o: HardOptions,
    *,
    target: Plan,
    target_rgb: RGB,
    buildings: Sequence[Building],
) -> World:
    """The world classes whose knobs are on, drawn in a fixed order; ``target`` is the
    target's plan (its own frame), ``buildings`` the scene's so far."""
    lighting = ground = texture = None
    areas: tuple[GroundArea, ...] = ()
    roofs = [b.color_rgb for b in buildings]
    if o.any_light:
        lighting = Lighting(
            sun_azimuth_deg=round(uniform(rng, 0.0, 360.0), 1) % 360.0,
            sun_elevation_deg=round(uniform(rng, 5.0, 90.0), 1),
            ambient=round(uniform(rng, 0.15, 0.8), 2),
        )
    tolerance_deg = GROUND_HUE_GAP_DEG if (o.any_ground or o.ground_areas) else 0.0
    if o.any_ground:
        ground = _fair(rng, _ground_colour, target_rgb, roofs, tolerance_deg)
    if o.ground_areas:
        areas = _areas(rng, o, target_rgb, roofs, tolerance_deg)
    if o.ground_texture:
        grain = rng.random() < 0.5
        scale = uniform(rng, 0.15, 0.5) if grain else uniform(rng, 1.0, 4.0)
        texture = GroundTexture(
            kind=TextureKind.GRAIN if grain else TextureKind.NOISE,
            amplitude_dn=round(uniform(rng, 4.0, 14.0), 1),
            scale_m=round(scale, 2),
            seed=_index(rng, 2**31),
        )
    near: list[Building] = []
    classes: list[str] = []
    if o.near_shapes:
        top_m = max(p.top_m for p in target.parts)
        for k in range(1 + _index(rng, 2)):
            made = _near_shape(rng, target, exclude=classes)
            if made is None:
                break
            kind, ring = made
            placed = _place(rng, o, ring, [*buildings, *near])
            if placed is None:
                break
            name = f"b{len(buildings) + k:02d}"
            near.append(Building(name, target_rgb, (Block(placed, 0.0, top_m),)))
            classes.append(kind)
    return World(lighting, ground, areas, texture, tuple(near), tuple(classes))


GROUND_HUE_GAP_DEG = 12.0
"""How far (degrees of hue) a drawn ground stays from the target's colour: the vectorizer's
default hue window (`uavtool.vision.VectorizeParams.hue_tolerance_deg`; a test keeps the two
equal), so the ground is never of the target's colour to the vision — a different, unfair
problem. A constant here, not an import: the world does not depend on the vision."""


# --------------------------------------------------------------------------- colours


def _hue_deg(rgb: RGB) -> float:
    return 360.0 * colorsys.rgb_to_hsv(rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0)[0]


def _hue_gap_deg(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def _fair(
    rng: random.Random,
    draw: Callable[[random.Random], RGB],
    target_rgb: RGB,
    roofs: Sequence[RGB],
    tolerance_deg: float,
) -> RGB | None:
    """A colour from ``draw`` at least ``tolerance_deg`` of hue from the target's and
    ``_CONTRAST_DN`` from every roof in some channel; None if 50 draws find none."""
    target_hue = _hue_deg(target_rgb)
    for _try in range(50):
        rgb = draw(rng)
        if _hue_gap_deg(_hue_deg(rgb), target_hue) < tolerance_deg:
            continue
        if all(_contrast_dn(rgb, roof) >= _CONTRAST_DN for roof in roofs):
            return rgb
    return None


def _contrast_dn(a: RGB, b: RGB) -> int:
    return max(abs(x - y) for x, y in zip(a, b, strict=True))


def _ground_colour(rng: random.Random) -> RGB:
    family = _index(rng, 3)
    if family == 0:  # grass
        return _hsv_rgb(uniform(rng, 75.0, 140.0), uniform(rng, 0.35, 0.75), uniform(rng, 0.3, 0.6))
    if family == 1:  # earth
        return _hsv_rgb(uniform(rng, 20.0, 45.0), uniform(rng, 0.35, 0.7), uniform(rng, 0.25, 0.55))
    return _hsv_rgb(uniform(rng, 0.0, 360.0), uniform(rng, 0.0, 0.8), uniform(rng, 0.2, 0.8))


def _area_colour(kind: str) -> Callable[[random.Random], RGB]:
    def draw(rng: random.Random) -> RGB:
        if kind == "lawn":
            hue, sat, val = (
                uniform(rng, 80.0, 135.0),
                uniform(rng, 0.35, 0.7),
                uniform(rng, 0.35, 0.65),
            )
        elif kind == "road":  # asphalt
            hue, sat, val = (
                uniform(rng, 0.0, 360.0),
                uniform(rng, 0.0, 0.08),
                uniform(rng, 0.18, 0.35),
            )
        elif kind == "car park":  # concrete
            hue, sat, val = (
                uniform(rng, 20.0, 60.0),
                uniform(rng, 0.0, 0.06),
                uniform(rng, 0.45, 0.7),
            )
        else:  # a field: earth to yellow-green
            hue, sat, val = (
                uniform(rng, 25.0, 70.0),
                uniform(rng, 0.3, 0.65),
                uniform(rng, 0.35, 0.7),
            )
        return _hsv_rgb(hue, sat, val)

    return draw


# --------------------------------------------------------------------------- areas


def _areas(
    rng: random.Random, o: HardOptions, target_rgb: RGB, roofs: Sequence[RGB], tol: float
) -> tuple[GroundArea, ...]:
    out: list[GroundArea] = []
    for k in range(2 + _index(rng, 5)):
        kind = _AREA_KINDS[_index(rng, len(_AREA_KINDS))]
        centre = (uniform(rng, -o.spread_m, o.spread_m), uniform(rng, -o.spread_m, o.spread_m))
        if kind == "road":  # through the town: long and narrow
            ring = _box(uniform(rng, 60.0, 120.0), uniform(rng, 5.0, 8.0))
        elif kind == "lawn":
            ring = _box(uniform(rng, 8.0, 25.0), uniform(rng, 8.0, 25.0))
        elif kind == "car park":
            ring = _box(uniform(rng, 15.0, 30.0), uniform(rng, 10.0, 20.0))
        else:
            n, r = 5 + _index(rng, 4), uniform(rng, 12.0, 25.0)
            step = 2.0 * math.pi / n
            angles = [i * step + 0.5 * step * rng.random() for i in range(n)]
            ring = tuple((r * math.cos(a), r * math.sin(a)) for a in angles)
        turn = rotation(2.0 * math.pi * rng.random())
        rgb = _fair(rng, _area_colour(kind), target_rgb, roofs, tol)
        if rgb is None:
            continue
        moved = [turn(p) for p in ring]
        polygon = normalise_ring(
            [(round(centre[0] + x, 2) + 0.0, round(centre[1] + y, 2) + 0.0) for x, y in moved]
        )
        out.append(GroundArea(f"{kind.replace(' ', '-')}{k + 1}", rgb, polygon))
    return tuple(out)


def _box(length: float, width: float) -> Ring:
    a, b = length / 2.0, width / 2.0
    return ((-a, -b), (a, -b), (a, b), (-a, b))


# --------------------------------------------------------------------------- near shapes


def _near_shape(
    rng: random.Random, target: Plan, *, exclude: Sequence[str]
) -> tuple[str, Ring] | None:
    """A near shape of the target's outline (own frame) of a class not in ``exclude``, as
    (class, ring); None if no class gives a well-formed ring in a few tries."""
    ring = target.outline
    classes = ["aspect", "chamfer", "notch"]
    if target.shape == "rectangle" and len(ring) == 4:
        classes.append("trapezoid")
    if target.shape in ("L", "T", "U", "cross") and rectilinear(ring):
        classes.append("arm")
    classes = [c for c in classes if c not in exclude]
    for _try in range(10):
        if not classes:
            return None
        kind = classes[_index(rng, len(classes))]
        out = _NEAR_MAKERS[kind](rng, ring)
        if out is not None and well_formed(out):
            return kind, normalise_ring(out)
    return None


def _aspect(rng: random.Random, ring: Ring) -> Ring | None:
    f = uniform(rng, 1.05, 1.10)
    f = f if rng.random() < 0.5 else 1.0 / f
    return tuple((f * x, y) for x, y in ring)


def _trapezoid(rng: random.Random, ring: Ring) -> Ring | None:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    inset = (1.0 - uniform(rng, 0.60, 0.95)) * (x1 - x0) / 2.0
    return ((x0, y0), (x1, y0), (x1 - inset, y1), (x0 + inset, y1))


def _corner(rng: random.Random, ring: Ring, *, notch: bool) -> Ring | None:
    convex = convex_corners(ring)
    corners = [k for k in range(len(ring)) if convex[k]]
    if not corners:
        return None
    k = corners[_index(rng, len(corners))]
    n = len(ring)
    p, prev, nxt = ring[k], ring[k - 1], ring[(k + 1) % n]
    cut = uniform(rng, 0.15, 0.30) * min(math.dist(p, prev), math.dist(p, nxt))
    to_prev = _unit(p, prev)
    to_next = _unit(p, nxt)
    a = (p[0] + cut * to_prev[0], p[1] + cut * to_prev[1])
    b = (p[0] + cut * to_next[0], p[1] + cut * to_next[1])
    new = [a, (a[0] + b[0] - p[0], a[1] + b[1] - p[1]), b] if notch else [a, b]
    return (*ring[:k], *new, *ring[k + 1 :])


def _unit(a: Point, b: Point) -> Point:
    d = math.dist(a, b)
    return ((b[0] - a[0]) / d, (b[1] - a[1]) / d)


def _arm(rng: random.Random, ring: Ring) -> Ring | None:
    """One wing (an edge between two convex corners) moved in by 15 % of its arm's length."""
    n = len(ring)
    convex = convex_corners(ring)
    wings = [k for k in range(n) if convex[k] and convex[(k + 1) % n]]
    if not wings:
        return None
    k = wings[_index(rng, len(wings))]
    k1 = (k + 1) % n
    arm = min(math.dist(ring[k - 1], ring[k]), math.dist(ring[k1], ring[(k + 2) % n]))
    return tuple(moved_wing(ring, k, 0.15 * arm, remove=False))


_NEAR_MAKERS: dict[str, Callable[[random.Random, Ring], Ring | None]] = {
    "aspect": _aspect,
    "trapezoid": _trapezoid,
    "chamfer": lambda rng, ring: _corner(rng, ring, notch=False),
    "notch": lambda rng, ring: _corner(rng, ring, notch=True),
    "arm": _arm,
}


def _place(
    rng: random.Random, o: HardOptions, ring: Ring, others: Sequence[Building]
) -> tuple[Point, ...] | None:
    """``ring`` turned any way and placed in the square of half-side ``spread_m`` (growing
    slowly while crowded), ``margin_m`` from every other footprint and ``_HOME_CLEAR_M`` from
    home, rounded to centimetres; None after 5,000 tries."""
    turn = rotation(2.0 * math.pi * rng.random())
    turned = [turn(p) for p in ring]
    radius = max(math.hypot(x, y) for x, y in turned)
    blocks = [
        (blk.footprint_enu_m, _circle(blk.footprint_enu_m)) for b in others for blk in b.blocks
    ]
    half = o.spread_m
    for _try in range(5000):
        ex, ny = uniform(rng, -half, half), uniform(rng, -half, half)
        half *= 1.001
        placed = normalise_ring(
            [(round(ex + x, 2) + 0.0, round(ny + y, 2) + 0.0) for x, y in turned]
        )
        if math.hypot(ex, ny) < radius + _HOME_CLEAR_M:
            continue
        if all(
            math.hypot(ex - c[0], ny - c[1]) >= radius + c[2] + o.margin_m
            or _apart(placed, fp, o.margin_m)
            for fp, c in blocks
        ):
            return placed
    return None


def _circle(ring: Sequence[Point]) -> tuple[float, float, float]:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return cx, cy, max(math.hypot(x - cx, y - cy) for x, y in ring)


def _apart(a: Sequence[Point], b: Sequence[Point], gap_m: float) -> bool:
    return not inside(a[0], b) and not inside(b[0], a) and ring_distance_m(a, b) >= gap_m
