"""Seeded random scenes: varied footprints, rotations, heights and distinct colours.

Only ``random.Random(seed).random()`` (Mersenne Twister, the same stream in every Python
version) and ``math`` feed the result, and coordinates are rounded to centimetres, so a
seed gives the same scene file on every machine. :mod:`uavtool.world.hard` builds on these
helpers for hard scenes (decoys of the target, stepped towers, arches, spread out).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable

from uavtool.geo import GeoPoint
from uavtool.world.errors import SceneError
from uavtool.world.limits import MAX_BUILDINGS
from uavtool.world.polygon import normalise_ring
from uavtool.world.scene import Block, Building, Scene, scene_from_dict, scene_to_dict

_SHAPES = ("rectangle", "L", "T", "U", "cross", "convex", "concave")

Ring = list[tuple[float, float]]


def generate_scene(*, seed: int, buildings: int, margin_m: float = 4.0) -> Scene:
    """A scene of ``buildings`` non-overlapping buildings at least ``margin_m`` apart.

    Footprints are rectangles, L, T, U, crosses, random convex and concave polygons of
    4–12 m, turned by a random angle, 3–10 m high, placed around home in a square that
    grows with the count. Raises SceneError for a count outside 1..MAX_BUILDINGS.
    """
    if not 1 <= buildings <= MAX_BUILDINGS:
        raise SceneError(f"--buildings must be in 1..{MAX_BUILDINGS}, got {buildings}")
    if not 0.0 <= margin_m <= 50.0:
        raise SceneError(f"margin must be 0..50 m, got {margin_m}")
    rng = random.Random(seed)
    half_side_m = 7.0 * math.sqrt(buildings) + 6.0
    placed: list[tuple[float, float, float]] = []  # centre east, north, bounding radius
    out: list[Building] = []
    hue_offset = rng.random() * 360.0
    for k in range(buildings):
        shape = _SHAPES[_index(rng, len(_SHAPES))]
        ring = _MAKERS[shape](rng)
        radius = max(math.sqrt(x * x + y * y) for x, y in ring)
        for _attempt in range(10_000):
            ex = (2.0 * rng.random() - 1.0) * half_side_m
            ny = (2.0 * rng.random() - 1.0) * half_side_m
            if all(
                math.sqrt((ex - px) ** 2 + (ny - py) ** 2) >= radius + pr + margin_m
                for px, py, pr in placed
            ):
                break
            half_side_m *= 1.001  # crowded: let the square grow slowly
        placed.append((ex, ny, radius))
        angle = rng.random() * 2.0 * math.pi
        c, s = math.cos(angle), math.sin(angle)
        footprint = normalise_ring(
            [
                (round(ex + c * x - s * y, 2) + 0.0, round(ny + s * x + c * y, 2) + 0.0)
                for x, y in ring
            ]
        )
        top = round(3.0 + 7.0 * rng.random(), 1)
        hue = (hue_offset + k * 360.0 / buildings) % 360.0
        out.append(Building(f"b{k:02d}", _hsv_rgb(hue, 0.75, 0.85), (Block(footprint, 0.0, top),)))
    target = out[_index(rng, len(out))].name
    scene = Scene(
        name=f"random-{seed}",
        home=GeoPoint(50.0647, 19.945, 219.0),
        home_heading_deg=0.0,
        buildings=tuple(out),
        target=target,
        description=f"uavtool scene random --seed {seed} --buildings {buildings}",
    )
    # what we write must load: run the file validation on it
    return scene_from_dict(scene_to_dict(scene), source=scene.name)


def _index(rng: random.Random, n: int) -> int:
    return min(int(rng.random() * n), n - 1)


def _size(rng: random.Random, lo: float = 4.0, hi: float = 12.0) -> float:
    return lo + (hi - lo) * rng.random()


def _rectangle(rng: random.Random) -> Ring:
    w, h = _size(rng) / 2.0, _size(rng) / 2.0
    return [(-w, -h), (w, -h), (w, h), (-w, h)]


def _ell(rng: random.Random) -> Ring:
    w, h = _size(rng, 6.0), _size(rng, 6.0)
    a, b = w * (0.3 + 0.3 * rng.random()), h * (0.3 + 0.3 * rng.random())
    return _centred([(0, 0), (w, 0), (w, b), (a, b), (a, h), (0, h)])


def _tee(rng: random.Random) -> Ring:
    w, h = _size(rng, 6.0), _size(rng, 6.0)
    stem, bar = w * (0.25 + 0.2 * rng.random()), h * (0.25 + 0.2 * rng.random())
    x0, x1 = (w - stem) / 2.0, (w + stem) / 2.0
    return _centred(
        [(x0, 0), (x1, 0), (x1, h - bar), (w, h - bar), (w, h), (0, h), (0, h - bar), (x0, h - bar)]
    )


def _you(rng: random.Random) -> Ring:
    w, h = _size(rng, 6.0), _size(rng, 6.0)
    arm, floor = w * (0.2 + 0.1 * rng.random()), h * (0.25 + 0.2 * rng.random())
    return _centred(
        [(0, 0), (w, 0), (w, h), (w - arm, h), (w - arm, floor), (arm, floor), (arm, h), (0, h)]
    )


def _cross(rng: random.Random) -> Ring:
    w, h = _size(rng, 6.0) / 2.0, _size(rng, 6.0) / 2.0
    a, b = w * (0.3 + 0.3 * rng.random()), h * (0.3 + 0.3 * rng.random())
    return [
        (-a, -h),
        (a, -h),
        (a, -b),
        (w, -b),
        (w, b),
        (a, b),
        (a, h),
        (-a, h),
        (-a, b),
        (-w, b),
        (-w, -b),
        (-a, -b),
    ]


def _radial(rng: random.Random, *, concave: bool) -> Ring:
    n = 5 + _index(rng, 4) if not concave else 6 + 2 * _index(rng, 3)
    r = _size(rng, 4.0, 10.0) / 2.0
    step = 2.0 * math.pi / n
    angles = [k * step + 0.5 * step * rng.random() for k in range(n)]  # increasing: a simple ring
    if concave:  # alternate outer and inner radii: a star
        radii = [r if k % 2 == 0 else r * (0.45 + 0.25 * rng.random()) for k in range(n)]
        return [(radii[k] * math.cos(a), radii[k] * math.sin(a)) for k, a in enumerate(angles)]
    # points on a circle in angular order, each gap under 180 degrees: a convex polygon
    return [(r * math.cos(a), r * math.sin(a)) for a in angles]


def _centred(ring: list[tuple[float, float]]) -> Ring:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return [(x - cx, y - cy) for x, y in ring]


_MAKERS: dict[str, Callable[[random.Random], Ring]] = {
    "rectangle": _rectangle,
    "L": _ell,
    "T": _tee,
    "U": _you,
    "cross": _cross,
    "convex": lambda rng: _radial(rng, concave=False),
    "concave": lambda rng: _radial(rng, concave=True),
}


def _hsv_rgb(hue_deg: float, sat: float, val: float) -> tuple[int, int, int]:
    h = hue_deg / 60.0
    sector = min(int(h), 5)
    f = h - sector
    p, q, t = val * (1.0 - sat), val * (1.0 - sat * f), val * (1.0 - sat * (1.0 - f))
    r, g, b = [(val, t, p), (q, val, p), (p, val, t), (p, q, val), (t, p, val), (val, p, q)][sector]
    return (round(r * 255.0), round(g * 255.0), round(b * 255.0))
