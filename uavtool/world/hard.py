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

The **town** classes (:meth:`HardOptions.town`, ``--town``; each off by default) add what a
real town has and the mission was not tuned on:

* **grey** roofs: concrete greys, white, black, grey-blue (HSV saturation under 70/255),
  their value 27 levels or more from the grey ground's;
* **darker shades**: a building of another's hue (the target's half the time), its value
  0.40–0.62 against the others' 0.85;
* same-colour decoys: a **hole** decoy, the target's outline filled solid when the target
  is a courtyard, or with a yard cut in when it is solid; a **wing** decoy, the target with
  one wing 2–4 m shorter or taken off; both in the target's exact colour and height;
* **courtyard** targets: a rectangle or an L of walls around an open yard, two blocks (a
  footprint is a simple polygon, so a through-hole takes a ring of blocks);
* **towers** 30–60 m tall (others, sometimes the target), one maybe 1–3 m from home;
* **dense** blocks: 12–16 buildings whose footprints are 2–3 m apart;
* **small** targets, 3–5 m across.

Every building is turned by a random angle; footprints stay ``margin_m`` apart, so nothing
stands over the target (a dense block's are its own 2–3 m apart). :class:`HardSceneInfo`
names the decoys by kind and the buildings of each town class, so a benchmark can count
mirror matches apart from other wrong matches, and break results down by class.

Determinism as in :mod:`uavtool.world.generator`: only ``random.Random(seed).random()``
and ``math`` feed the result (shuffles and choices are written out here), coordinates are
rounded to centimetres and heights to decimetres, so a seed gives the same scene everywhere.
A town class draws only when its knob is above 0, so with them off every seed gives the
scene it always gave.
Building plans are made in :mod:`uavtool.world.hard_shapes`, the plane geometry is in
:mod:`uavtool.world.hard_geometry`.
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, fields, replace

from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.world.errors import SceneError
from uavtool.world.generator import _hsv_rgb, _index
from uavtool.world.hard_geometry import (
    Point,
    Ring,
    inside,
    is_chiral,
    point_segment_m,
    ring_distance_m,
    rotation,
)
from uavtool.world.hard_shapes import (
    ARCHES,
    SHAPES,
    Plan,
    arch_plan,
    courtyard_plan,
    filled_copy,
    mapped,
    near_copy,
    over_home_arch,
    plain_or_stepped,
    small_plan,
    uniform,
    wing_copy,
    yard_copy,
)
from uavtool.world.hard_world import World, draw_world
from uavtool.world.polygon import normalise_ring
from uavtool.world.scene import (
    DEFAULT_GROUND_RGB,
    Block,
    Building,
    Lighting,
    Scene,
    scene_from_dict,
    scene_to_dict,
)

MAX_HARD_BUILDINGS = 16  # hue slots stay >= 22.5° apart, so the mirror decoy's hue is nearest
HOME = GeoPoint(50.0647, 19.945, 219.0)  # the paper scene's home

TOWER_M = (30.0, 60.0)  # a tower's roof is this high (whatever max_height_m says)
_TOWER_SHAPES = ("rectangle", "L", "convex")  # a tower beside home: always a spot beside it
_HOME_CLEAR_M = 4.0  # buildings not deliberately beside or over home keep this far from it
_DENSE_HALF_M = 10.0  # a dense block's square starts this wide (half-side) and grows
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
    anywhere: bool = False  # home anywhere on Earth to ±85° latitude, in a third of the
    # scenes within `spread_m` of the 180th meridian (the buildings straddle it); the vehicle
    # turned any way. Wins over random_home; drawn after everything else, as it is
    # The world classes (issue 45; `--world` turns them all on), each drawn after all of
    # the above, home included, and only when on (see uavtool.world.hard_world):
    any_light: bool = False  # the sun 5–90° up from any azimuth, ambient 0.15–0.8
    any_ground: bool = False  # ground of any colour, its hue away from the target's
    ground_areas: bool = False  # 2–6 lawns, roads, car parks and fields around home
    ground_texture: bool = False  # seeded grain or noise on the ground, 4–14 DN
    near_shapes: bool = False  # 1–2 near shapes of the target, in its colour and height
    # The town classes (HardOptions.town() turns them all on); each is drawn once per scene,
    # and only when its knob is above 0, so scenes without them are as they always were.
    grey_p: float = 0.0  # 1–3 other buildings concrete grey, white, black or grey-blue
    darker_p: float = 0.0  # 1–2 other buildings a clearly darker shade of another's hue
    hole_decoy_p: float = 0.0  # the target's colour, differing by a yard (filled or cut in)
    wing_decoy_p: float = 0.0  # the target's colour, one wing 2–4 m shorter or taken off
    courtyard_target_p: float = 0.0  # the target is a rectangle or L around an open yard
    small_target_p: float = 0.0  # the target is 3–5 m across (never a courtyard or arch)
    target_tower_p: float = 0.0  # the target is 30–60 m tall (never small or an arch)
    tower_p: float = 0.0  # 1–2 other buildings are 30–60 m towers
    home_tower_p: float = 0.0  # a 30–60 m tower 1–3 m from home (home_overhang_p wins)
    dense_p: float = 0.0  # 12–16 buildings, 2–3 m apart (the count options do not apply)

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

    def with_world(self) -> HardOptions:
        """These options with every world class on (`--world`)."""
        return replace(self, **dict.fromkeys(WORLD_KNOBS, True))

    @classmethod
    def town(cls) -> HardOptions:
        """The town preset (`uavtool scene random --hard --town`): every town class on, each
        in roughly a fifth to two fifths of the scenes (dense blocks in about a fifth), on
        top of the hard scene's decoys, stepped towers and arches."""
        return cls(
            min_buildings=6,
            max_buildings=9,
            home_overhang_p=0.12,
            grey_p=0.35,
            darker_p=0.35,
            hole_decoy_p=0.45,
            wing_decoy_p=0.35,
            courtyard_target_p=0.25,
            small_target_p=0.25,
            target_tower_p=0.15,
            tower_p=0.2,
            home_tower_p=0.2,
            dense_p=0.2,
        )


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
    # the town classes (HardOptions' town knobs); empty when off
    hole_decoy: str | None = None  # target's colour: its outline filled, or a yard cut in
    wing_decoy: str | None = None  # target's colour: one wing 2–4 m shorter or taken off
    courtyards: tuple[str, ...] = ()  # buildings around an open yard (target_kind courtyard)
    small_target: bool = False  # the target is 3–5 m across
    towers: tuple[str, ...] = ()  # 30–60 m tall: towers, a tower target and its copies
    home_tower: str | None = None  # beside_home when that is a tower (home_tower_p or not)
    grey: tuple[str, ...] = ()  # saturation under 70/255: concrete, white, black, grey-blue
    darker: tuple[tuple[str, str], ...] = ()  # (building, the brighter one of its hue)
    dense_gap_m: float | None = None  # a dense block: least gap between footprints
    # the world classes (HardOptions' world knobs); empty when off
    near_shapes: tuple[tuple[str, str], ...] = ()  # (building, class): target's colour
    world: tuple[str, ...] = ()  # light, ground, areas, texture, as the description says

    @property
    def decoys(self) -> tuple[str, ...]:
        """Names of all decoys of the target."""
        found = (
            self.mirror_decoy,
            self.scaled_decoy,
            self.near_decoy,
            self.hole_decoy,
            self.wing_decoy,
        )
        return tuple(n for n in found if n is not None) + tuple(n for n, _ in self.near_shapes)

    @property
    def classes(self) -> tuple[str, ...]:
        """The :data:`TOWN_CLASSES` this scene holds, in that order."""
        held = {
            "grey": bool(self.grey),
            "darker shade": bool(self.darker),
            "darker shade of the target": any(b == self.target for _, b in self.darker),
            "hole decoy": self.hole_decoy is not None,
            "wing decoy": self.wing_decoy is not None,
            "courtyard target": self.target_kind == "courtyard",
            "tower": bool(self.towers),
            "tower target": self.target in self.towers,
            "home beside a tower": self.home_tower is not None,
            "home under a deck": self.over_home is not None,
            "dense": self.dense_gap_m is not None,
            "small target": self.small_target,
        }
        return tuple(c for c in TOWN_CLASSES if held[c])

    def summary(self) -> str:
        """One line, e.g. ``target b03 (stepped L); mirror decoy b05; arches b01``."""
        kind = "" if self.target_kind == "plain" else f"{self.target_kind} "
        small = "small " if self.small_target else ""
        out = [f"target {self.target} ({small}{kind}{self.target_shape})"]
        for label, name in (
            ("mirror decoy", self.mirror_decoy),
            ("near decoy", self.near_decoy),
            ("scaled decoy", self.scaled_decoy),
            ("hole decoy", self.hole_decoy),
            ("wing decoy", self.wing_decoy),
            ("home beside", self.beside_home),
            ("home tower", self.home_tower),
            ("arch over home", self.over_home),
        ):
            if name is not None:
                out.append(f"{label} {name}")
        for label, names in (
            ("stepped", self.stepped),
            ("arches", self.arches),
            ("courtyards", self.courtyards),
            ("towers", self.towers),
            ("grey", self.grey),
        ):
            if names:
                out.append(f"{label} {' '.join(names)}")
        if self.darker:
            out.append("darker " + " ".join(f"{a} (of {b})" for a, b in self.darker))
        if self.dense_gap_m is not None:
            out.append(f"dense, {self.dense_gap_m:g} m gaps")
        if self.near_shapes:
            out.append("near shapes " + " ".join(f"{n} ({c})" for n, c in self.near_shapes))
        out.extend(self.world)
        return "; ".join(out)


TOWN_CLASSES = (
    "grey",
    "darker shade",
    "darker shade of the target",
    "hole decoy",
    "wing decoy",
    "courtyard target",
    "tower",
    "tower target",
    "home beside a tower",
    "home under a deck",
    "dense",
    "small target",
)
"""The town classes :attr:`HardSceneInfo.classes` names (a benchmark's breakdown rows)."""


def generate_hard_scene(*, seed: int, options: HardOptions = HardOptions()) -> Scene:
    """A hard scene for ``seed`` (see the module doc); the scene of
    :func:`generate_hard_scene_with_info`."""
    return generate_hard_scene_with_info(seed=seed, options=options)[0]


# --------------------------------------------------------------------------- the scene


def generate_hard_scene_with_info(
    *, seed: int, options: HardOptions = HardOptions()
) -> tuple[Scene, HardSceneInfo]:
    """A hard scene for ``seed`` and what makes it hard.

    The count is drawn in ``[min_buildings, max_buildings]`` (12–16 in a dense block);
    decoys take places in that count (a tower beside home first, then mirror, near, scaled,
    hole, wing) and are left out when there is no room; towers, grey and darker buildings
    are among the others, so they too need room. Building centres are drawn in a square of
    half-side ``spread_m`` around home (it grows slowly if crowded; a dense block starts
    small); names ``b00``… are in a seeded order, so the target's name says nothing. The
    description holds the command that makes the scene again. Raises SceneError only if
    the result fails the scene-file validation (a bug).
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
    town = _town_draws(rng, o, over_home=over_home)
    if town.dense_gap_m is not None:
        n = town.count
    if town.home_tower:
        beside = False  # the tower is the building beside home
    tall = _tall(o)

    # a mirror decoy of a symmetric target would be a plain copy: only chiral targets get one
    target, want_mirror = _target_plan(
        rng,
        o,
        arch=target_arch and not (town.courtyard or town.small or town.target_tower),
        chiral=want_mirror,
        courtyard=town.courtyard,
        small=town.small,
        tall=town.target_tower,
    )
    roles: list[tuple[str, Plan]] = [("target", target)]
    home_local: Point = (0.0, 0.0)
    if over_home:
        arch, home_local = over_home_arch(rng, o)
        roles.append(("over_home", arch))
    if town.home_tower and len(roles) < n:
        roles.append(("home_tower", plain_or_stepped(rng, tall, _TOWER_SHAPES[_index(rng, 3)])))
    if want_mirror and len(roles) < n:
        roles.append(("mirror", mapped(target, lambda p: (-p[0], p[1]))))
    if want_near and len(roles) < n:
        near = near_copy(rng, target)
        if near is not None:
            roles.append(("near", near))
    if want_scaled and len(roles) < n:
        s = uniform(rng, 0.6, 1.5)
        roles.append(("scaled", mapped(target, lambda p: (s * p[0], s * p[1]))))
    if town.hole and len(roles) < n:
        hole = filled_copy(target) if target.yard is not None else yard_copy(rng, target)
        if hole is not None:
            roles.append(("hole", hole))
    if town.wing and len(roles) < n:
        wing = wing_copy(rng, target)
        if wing is not None:
            roles.append(("wing", wing))
    first_other = len(roles)
    while len(roles) < n:
        if len(roles) - first_other < town.towers:
            plan = plain_or_stepped(rng, tall, SHAPES[_index(rng, len(SHAPES))])
        elif rng.random() < o.arch_p:
            plan = arch_plan(rng, o, ARCHES[_index(rng, len(ARCHES))])
        else:
            plan = plain_or_stepped(rng, o, SHAPES[_index(rng, len(SHAPES))])
        roles.append(("other", plan))
    others = list(range(first_other, n))
    grey = others[len(others) - min(town.grey, len(others)) :]
    darker = [i for i in others if i not in grey][-town.darker :] if town.darker else []

    # hues: the hole and wing decoys are the target's colour; grey and darker ones take none
    slotted = [i for i, (r, _) in enumerate(roles) if r not in ("hole", "wing")]
    slotted = [i for i in slotted if i not in grey and i not in darker]
    hues = [0.0] * n
    for i, hue in zip(slotted, _hues(rng, [roles[i][0] for i in slotted], hue0), strict=True):
        hues[i] = hue
    colours = [_hsv_rgb(h, 0.75, 0.85) for h in hues]
    for i, (r, _) in enumerate(roles):
        if r in ("hole", "wing"):
            colours[i] = colours[0]
    for i in grey:
        colours[i] = _grey(rng)
    brighter = [i for i in slotted if roles[i][0] == "other"]  # and the target
    shade_of: dict[int, int] = {}
    for i in darker:  # the target's hue half the time
        pick = not brighter or rng.random() < 0.5
        shade_of[i] = 0 if pick else brighter[_index(rng, len(brighter))]
        colours[i] = _hsv_rgb(hues[shade_of[i]], 0.75, uniform(rng, 0.4, 0.62))

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
    home_tower = next((i for i, (r, _) in enumerate(roles) if r == "home_tower"), None)
    if home_tower is not None:
        spot = _beside_home(rng, turned[home_tower].outline)
        if spot is not None:
            centres[home_tower], beside_index = (-spot[0], -spot[1]), home_tower
    if town.dense_gap_m is None:
        _place(rng, o, turned, centres)
    else:
        _place_tight(rng, turned, centres, town.dense_gap_m)

    order = _permutation(rng, n)  # order[position] = role index
    name_of = {i: f"b{pos:02d}" for pos, i in enumerate(order)}
    buildings = tuple(_building(name_of[i], colours[i], turned[i], centres[i]) for i in order)

    def named(role: str) -> str | None:
        return next((name_of[i] for i, (r, _) in enumerate(roles) if r == role), None)

    def names(indices: Iterable[int]) -> tuple[str, ...]:
        return tuple(sorted(name_of[i] for i in indices))

    copies = ("mirror", "near", "scaled", "hole", "wing")
    towers = [
        i
        for i, (r, _) in enumerate(roles)
        if r == "home_tower"
        or (town.target_tower and (i == 0 or r in copies))
        or first_other <= i < first_other + town.towers
    ]
    info = HardSceneInfo(
        target=name_of[0],
        target_shape=target.shape,
        target_kind=target.kind,
        mirror_decoy=named("mirror"),
        scaled_decoy=named("scaled"),
        near_decoy=named("near"),
        stepped=names(i for i, p in enumerate(turned) if p.kind == "stepped"),
        arches=names(i for i, p in enumerate(turned) if p.kind == "arch"),
        beside_home=None if beside_index is None else name_of[beside_index],
        over_home=named("over_home"),
        hole_decoy=named("hole"),
        wing_decoy=named("wing"),
        courtyards=names(i for i, p in enumerate(turned) if p.kind == "courtyard"),
        small_target=town.small,
        towers=names(towers),
        home_tower=None if beside_index not in towers else name_of[beside_index],
        grey=names(grey),
        darker=tuple(sorted((name_of[i], name_of[j]) for i, j in shade_of.items())),
        dense_gap_m=town.dense_gap_m,
    )
    home, heading_deg = HOME, 0.0
    if o.anywhere:
        lat = uniform(rng, -85.0, 85.0)
        if rng.random() < 1.0 / 3.0:  # the 180th meridian through the town
            on_line = GeoPoint(lat, 180.0, HOME.alt_amsl_m)
            off_line = geo_from_enu(on_line, uniform(rng, -o.spread_m, o.spread_m), 0.0, 0.0)
            lon = off_line.lon_deg
        else:
            lon = uniform(rng, -180.0, 180.0)
        home = GeoPoint(round(lat, 7), round(lon, 7), HOME.alt_amsl_m)
        heading_deg = round(uniform(rng, 0.0, 360.0), 1) % 360.0
    elif o.random_home:
        lat, lon = uniform(rng, -60.0, 60.0), uniform(rng, -180.0, 180.0)
        home = GeoPoint(round(lat, 7), round(lon, 7), HOME.alt_amsl_m)
        heading_deg = round(uniform(rng, 0.0, 360.0), 1) % 360.0
    world = draw_world(rng, o, target=target, target_rgb=colours[0], buildings=buildings)
    if world != World():
        info = replace(
            info,
            near_shapes=tuple(
                (b.name, c) for b, c in zip(world.near_shapes, world.near_classes, strict=True)
            ),
            world=world.labels(),
        )
    scene = Scene(
        name=f"hard-{seed}",
        home=home,
        home_heading_deg=heading_deg,
        buildings=buildings + world.near_shapes,
        target=info.target,
        description=f"{hard_command(seed, o)}: {info.summary()}",
        ground_rgb=world.ground_rgb or DEFAULT_GROUND_RGB,
        lighting=world.lighting or Lighting(),
        ground_areas=world.areas,
        ground_texture=world.texture,
    )
    # what we write must load: run the file validation on it
    return scene_from_dict(scene_to_dict(scene), source=scene.name), info


@dataclass(frozen=True, slots=True)
class _Town:
    """The town classes drawn for one scene (all off unless their knobs are on)."""

    dense_gap_m: float | None = None
    count: int = 0  # buildings in a dense block
    courtyard: bool = False
    small: bool = False
    target_tower: bool = False
    home_tower: bool = False
    hole: bool = False
    wing: bool = False
    towers: int = 0
    grey: int = 0
    darker: int = 0


def _town_draws(rng: random.Random, o: HardOptions, *, over_home: bool) -> _Town:
    """Each class's draws happen only when its knob is on: with them all off the stream of
    draws (and so every older scene) is what it was."""
    dense = _chance(rng, o.dense_p)
    count, gap = 0, None
    if dense:
        count = min(12 + _index(rng, 5), MAX_HARD_BUILDINGS)
        gap = round(uniform(rng, 2.0, 3.0), 1)
    courtyard = _chance(rng, o.courtyard_target_p)
    small = not courtyard and _chance(rng, o.small_target_p)
    return _Town(
        dense_gap_m=gap,
        count=count,
        courtyard=courtyard,
        small=small,
        target_tower=not small and _chance(rng, o.target_tower_p),
        home_tower=not over_home and _chance(rng, o.home_tower_p),
        hole=_chance(rng, o.hole_decoy_p),
        wing=_chance(rng, o.wing_decoy_p),
        towers=1 + _index(rng, 2) if _chance(rng, o.tower_p) else 0,
        grey=1 + _index(rng, 3) if _chance(rng, o.grey_p) else 0,
        darker=1 + _index(rng, 2) if _chance(rng, o.darker_p) else 0,
    )


def _chance(rng: random.Random, p: float) -> bool:
    """True with probability ``p``; no draw at all when ``p`` is 0 (an option left off)."""
    return p > 0.0 and rng.random() < p


def _tall(o: HardOptions) -> HardOptions:
    """``o`` for a tower: every roof 30–60 m up."""
    return replace(o, min_height_m=TOWER_M[0], max_height_m=TOWER_M[1])


def _grey(rng: random.Random) -> tuple[int, int, int]:
    """A roof of saturation under 70/255 (at most 0.25) whose value stays 27 levels or more
    from the default ground's 128: light or dark concrete, white, black, or a grey-blue."""
    kind = _index(rng, 5)
    if kind == 0:  # light concrete
        hue, sat, val = uniform(rng, 20.0, 60.0), uniform(rng, 0.0, 0.08), uniform(rng, 0.62, 0.8)
    elif kind == 1:  # dark concrete
        hue, sat, val = uniform(rng, 20.0, 60.0), uniform(rng, 0.0, 0.08), uniform(rng, 0.25, 0.39)
    elif kind == 2:  # white
        hue, sat, val = uniform(rng, 0.0, 360.0), uniform(rng, 0.0, 0.04), uniform(rng, 0.9, 0.98)
    elif kind == 3:  # black
        hue, sat, val = uniform(rng, 0.0, 360.0), uniform(rng, 0.0, 0.1), uniform(rng, 0.08, 0.2)
    else:  # grey-blue (slate, zinc), light or dark
        hue, sat = uniform(rng, 200.0, 225.0), uniform(rng, 0.12, 0.25)
        val = uniform(rng, 0.62, 0.8) if rng.random() < 0.5 else uniform(rng, 0.3, 0.39)
    return _hsv_rgb(hue, sat, val)


def _target_plan(
    rng: random.Random,
    o: HardOptions,
    *,
    arch: bool,
    chiral: bool,
    courtyard: bool = False,
    small: bool = False,
    tall: bool = False,
) -> tuple[Plan, bool]:
    """The target's plan, and whether it is chiral (tried up to 100 times if ``chiral``)."""
    tries = 0
    heights = _tall(o) if tall else o
    while True:
        tries += 1
        if courtyard:
            plan = courtyard_plan(rng, heights)
        elif small:
            plan = small_plan(rng, o)
        elif arch:
            plan = arch_plan(rng, o, ARCHES[_index(rng, len(ARCHES))])
        else:
            plan = plain_or_stepped(rng, heights, SHAPES[_index(rng, len(SHAPES))])
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


def _place_tight(
    rng: random.Random, plans: Sequence[Plan], centres: list[Point | None], gap_m: float
) -> None:
    """Fill the missing centres of a dense block: drawn in a square of half-side
    ``_DENSE_HALF_M`` that grows slowly while crowded, footprints (not bounding circles)
    ``gap_m`` apart and ``_HOME_CLEAR_M`` from home."""
    radius = [max(math.hypot(x, y) for x, y in p.outline) for p in plans]

    def ring_at(i: int, c: Point) -> Ring:
        return tuple((c[0] + x, c[1] + y) for x, y in plans[i].outline)

    placed = [(i, c, ring_at(i, c)) for i, c in enumerate(centres) if c is not None]
    half = _DENSE_HALF_M
    gap = gap_m + _ROUND_SLACK_M
    for i, c in enumerate(centres):
        if c is not None:
            continue
        r = radius[i]
        while True:
            ex, ny = (2.0 * rng.random() - 1.0) * half, (2.0 * rng.random() - 1.0) * half
            ring = ring_at(i, (ex, ny))
            if (
                math.hypot(ex, ny) >= r + _HOME_CLEAR_M
                or _from_home_m(ring) >= _HOME_CLEAR_M + _ROUND_SLACK_M
            ) and all(
                math.hypot(ex - q[0], ny - q[1]) >= r + radius[j] + gap
                or ring_distance_m(ring, other) >= gap
                for j, q, other in placed
            ):
                break
            half *= 1.002
        placed.append((i, (ex, ny), ring))
        centres[i] = (ex, ny)


def _from_home_m(ring: Ring) -> float:
    home = (0.0, 0.0)
    if inside(home, ring):
        return 0.0
    return min(point_segment_m(home, ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring)))


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


def _building(
    name: str, colour: tuple[int, int, int], plan: Plan, centre: Point | None
) -> Building:
    ex, ny = centre if centre is not None else (0.0, 0.0)

    def at(p: Point) -> Point:
        return (round(ex + p[0], 2) + 0.0, round(ny + p[1], 2) + 0.0)  # + 0.0: no -0.0

    blocks = tuple(
        Block(normalise_ring([at(p) for p in part.ring]), part.base_m, part.top_m)
        for part in plan.parts
    )
    return Building(name, colour, blocks)


def hard_command(seed: int, options: HardOptions = HardOptions()) -> str:
    """The ``uavtool scene random --hard`` command line that makes this scene; options the
    command has no flag for are listed after it. Options whose town knobs are the town
    preset's are written ``--town`` and the rest compared with that preset."""
    default = HardOptions()
    words = ["uavtool scene random --hard"]
    town = HardOptions.town()
    if any(getattr(town, f) != getattr(default, f) for f in _TOWN_ONLY) and all(
        getattr(options, f) == getattr(town, f) for f in _TOWN_ONLY
    ):
        words.append("--town")
        default = town
    words.append(f"--seed {seed}")
    rest: list[str] = []
    counts = (options.min_buildings, options.max_buildings)
    if counts != (default.min_buildings, default.max_buildings):
        if counts[0] == counts[1]:
            words.append(f"--buildings {counts[0]}")
        else:
            rest += [f"min_buildings={counts[0]}", f"max_buildings={counts[1]}"]
    flags = {"margin_m": "--margin", "spread_m": "--spread"}
    every_world = all(getattr(options, f) for f in WORLD_KNOBS)
    for f in fields(options):
        value, was = getattr(options, f.name), getattr(default, f.name)
        if f.name in ("min_buildings", "max_buildings") or value == was:
            continue
        if f.name in WORLD_KNOBS:
            if not every_world:
                words.append(WORLD_KNOBS[f.name])
            elif f.name == next(iter(WORLD_KNOBS)):
                words.append("--world")
            continue
        if f.name in flags:
            words.append(f"{flags[f.name]} {value:g}")
        elif f.name == "home_overhang_p" and value == 1.0:
            words.append("--overhang")
        elif f.name == "random_home":
            words.append("--random-home")
        elif f.name == "anywhere":
            words.append("--anywhere")
        else:
            rest.append(f"{f.name}={value:g}")
    line = " ".join(words)
    return f"{line} (HardOptions: {', '.join(rest)})" if rest else line


WORLD_KNOBS = {
    "any_light": "--light",
    "any_ground": "--ground-colour",
    "ground_areas": "--ground-areas",
    "ground_texture": "--texture",
    "near_shapes": "--near-shapes",
}
"""The world classes' HardOptions fields and their flags (``--world``: all of them)."""

# what `--town` sets that no other flag of the command does
_TOWN_ONLY = tuple(
    f.name
    for f in fields(HardOptions)
    if f.name not in ("min_buildings", "max_buildings", "margin_m", "spread_m", "home_overhang_p")
    and f.name not in ("random_home", "anywhere", *WORLD_KNOBS)
)
