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
Building plans are made in :mod:`uavtool.world.hard_shapes`, the plane geometry is in
:mod:`uavtool.world.hard_geometry`.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass, fields

from uavtool.geo import GeoPoint
from uavtool.world.errors import SceneError
from uavtool.world.generator import _hsv_rgb, _index
from uavtool.world.hard_geometry import Point, Ring, inside, is_chiral, point_segment_m, rotation
from uavtool.world.hard_shapes import (
    ARCHES,
    SHAPES,
    Plan,
    arch_plan,
    mapped,
    near_copy,
    over_home_arch,
    plain_or_stepped,
    uniform,
)
from uavtool.world.polygon import normalise_ring
from uavtool.world.scene import Block, Building, Scene, scene_from_dict, scene_to_dict

MAX_HARD_BUILDINGS = 16  # hue slots stay >= 22.5° apart, so the mirror decoy's hue is nearest
HOME = GeoPoint(50.0647, 19.945, 219.0)  # the paper scene's home

_HOME_CLEAR_M = 4.0  # buildings not deliberately beside or over home keep this far from it
_ROUND_SLACK_M = 0.02  # centimetre rounding moves a footprint by up to ~1.5 cm


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
    random_home: bool = False  # home anywhere within ±60° latitude, the vehicle turned any
    # way (drawn after everything else: the buildings around home are the seed's own)

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
    roles: list[tuple[str, Plan]] = [("target", target)]
    home_local: Point = (0.0, 0.0)
    if over_home:
        arch, home_local = over_home_arch(rng, o)
        roles.append(("over_home", arch))
    if want_mirror and len(roles) < n:
        roles.append(("mirror", mapped(target, lambda p: (-p[0], p[1]))))
    if want_near and len(roles) < n:
        near = near_copy(rng, target)
        if near is not None:
            roles.append(("near", near))
    if want_scaled and len(roles) < n:
        s = uniform(rng, 0.6, 1.5)
        roles.append(("scaled", mapped(target, lambda p: (s * p[0], s * p[1]))))
    while len(roles) < n:
        if rng.random() < o.arch_p:
            plan = arch_plan(rng, o, ARCHES[_index(rng, len(ARCHES))])
        else:
            plan = plain_or_stepped(rng, o, SHAPES[_index(rng, len(SHAPES))])
        roles.append(("other", plan))

    hues = _hues(rng, [r for r, _ in roles], hue0)
    angles = [2.0 * math.pi * rng.random() for _ in roles]
    turned = [mapped(plan, rotation(a)) for (_, plan), a in zip(roles, angles, strict=True)]
    centres: list[Point | None] = [None] * n
    if over_home:
        hx, hy = rotation(angles[1])(home_local)
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
    home, heading_deg = HOME, 0.0
    if o.random_home:
        lat, lon = uniform(rng, -60.0, 60.0), uniform(rng, -180.0, 180.0)
        home = GeoPoint(round(lat, 7), round(lon, 7), HOME.alt_amsl_m)
        heading_deg = round(uniform(rng, 0.0, 360.0), 1) % 360.0
    scene = Scene(
        name=f"hard-{seed}",
        home=home,
        home_heading_deg=heading_deg,
        buildings=buildings,
        target=info.target,
        description=f"{hard_command(seed, o)}: {info.summary()}",
    )
    # what we write must load: run the file validation on it
    return scene_from_dict(scene_to_dict(scene), source=scene.name), info


def _target_plan(
    rng: random.Random, o: HardOptions, *, arch: bool, chiral: bool
) -> tuple[Plan, bool]:
    """The target's plan, and whether it is chiral (tried up to 100 times if ``chiral``)."""
    tries = 0
    while True:
        tries += 1
        if arch:
            plan = arch_plan(rng, o, ARCHES[_index(rng, len(ARCHES))])
        else:
            plan = plain_or_stepped(rng, o, SHAPES[_index(rng, len(SHAPES))])
        if not chiral:
            return plan, False
        if is_chiral(plan.outline) or tries == 100:
            return plan, is_chiral(plan.outline)


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


def _place(
    rng: random.Random, o: HardOptions, plans: Sequence[Plan], centres: list[Point | None]
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


def _beside_home(rng: random.Random, ring: Ring) -> Point | None:
    """Where home is, in the (turned) ring's frame, 1.1–2.9 m outside it; None if no try
    finds a spot whose nearest edge is that one (inside a U's notch, say)."""
    n = len(ring)
    for _try in range(20):
        k = _index(rng, n)
        a, b = ring[k], ring[(k + 1) % n]
        length = math.dist(a, b)
        nx, ny = (b[1] - a[1]) / length, (a[0] - b[0]) / length  # outward: ring is CCW
        t, gap = uniform(rng, 0.25, 0.75), uniform(rng, 1.1, 2.9)
        p = (a[0] + t * (b[0] - a[0]) + gap * nx, a[1] + t * (b[1] - a[1]) + gap * ny)
        nearest = min(point_segment_m(p, ring[i], ring[(i + 1) % n]) for i in range(n))
        if 1.1 <= nearest <= 2.9 and not inside(p, ring):
            return p
    return None


def _permutation(rng: random.Random, n: int) -> list[int]:
    out = list(range(n))
    for i in range(n - 1, 0, -1):  # Fisher–Yates, written out: random.shuffle may change
        j = _index(rng, i + 1)
        out[i], out[j] = out[j], out[i]
    return out


def _building(name: str, hue: float, plan: Plan, centre: Point | None) -> Building:
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
        elif f.name == "random_home":
            words.append("--random-home")
        else:
            rest.append(f"{f.name}={value:g}")
    line = " ".join(words)
    return f"{line} (HardOptions: {', '.join(rest)})" if rest else line
