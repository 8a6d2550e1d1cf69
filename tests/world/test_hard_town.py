"""The town classes of the hard-scene generator (`uavtool scene random --hard --town`): grey
and darker roofs, same-colour decoys that differ by a yard or a wing, courtyard and small
targets, tall towers, home beside a tower, dense blocks; and that scenes without them are
byte for byte the ones the generator always made."""

from __future__ import annotations

import colorsys
import hashlib
import itertools
import math
import time
from dataclasses import fields
from functools import cache
from pathlib import Path

import pytest
import shapely
from click.testing import CliRunner
from shapely import affinity
from shapely.geometry.polygon import orient

from tests.world.test_hard import _best_fit_m, _hue_gap
from uavtool.cli import cli
from uavtool.world import building_mesh, load_scene
from uavtool.world.hard import (
    TOWER_M,
    TOWN_CLASSES,
    HardOptions,
    HardSceneInfo,
    generate_hard_scene_with_info,
    hard_command,
)
from uavtool.world.scene import Building, Scene, dump_scene, scene_from_dict, scene_to_dict

TOWN_SEEDS = range(1, 201)
TOWN_KNOBS = (
    "grey_p",
    "darker_p",
    "hole_decoy_p",
    "wing_decoy_p",
    "courtyard_target_p",
    "small_target_p",
    "target_tower_p",
    "tower_p",
    "home_tower_p",
    "dense_p",
)
# sha256 of dump_scene() as the generator before the town classes (commit 517577f) wrote
# them: (options, seed) -> digest. A change means old seeds no longer give old scenes.
OLD_SCENES = {
    ("default", 1): "5091fff419451af46046cea749259f01c4720eb1058b0363d06f96579b45139f",
    ("default", 7): "2e768e1adc42e33ba242ecf9b21e60edd2f6f0e116083003a89a0e17476e8c95",
    ("default", 42): "03e282ccbd396daee4840eb93671a20366c4239c88ce77f1931c69ba0dc860d0",
    ("default", 123): "4269f24c7140f1019d7df37abf958863eafe0a913eea68af99a45f84f4b444e8",
    ("default", 250): "e39d8665e22dfa70b36364fe8a1acf7c85a18c9a4c3d6619d0592d2c808b923c",
    ("random_home", 3): "7f8eaa23d7d7467050f4dd89bfd9ea9ef23d815f08248fbdbd0e8b5328e6e6d9",
    ("overhang", 5): "0e96c3d0e074dd2ee409fa1fc866916e66b739fdbf3fe017954bd96633c3f946",
    ("many", 11): "591e24529e289942e5e69a87674e98e5d194996c61cc11030833a79c915dad5a",
    ("all", 17): "e7ae8dd4a63556a84433507a43ca9cf81dbfd29456f7f846ac95768362a9f463",
}
OLD_OPTIONS = {
    "default": HardOptions(),
    "random_home": HardOptions(random_home=True),
    "overhang": HardOptions(home_overhang_p=1.0),
    "many": HardOptions(min_buildings=12, max_buildings=16, spread_m=60.0, margin_m=3.0),
    "all": HardOptions(
        mirror_decoy_p=1.0,
        near_decoy_p=1.0,
        scaled_decoy_p=1.0,
        home_beside_p=1.0,
        stepped_p=0.6,
        arch_p=0.5,
        target_arch_p=0.5,
    ),
}
GROUND_V = 128  # the scenes' ground is [128, 128, 128]


@cache
def _town() -> tuple[tuple[Scene, HardSceneInfo], ...]:
    return tuple(
        generate_hard_scene_with_info(seed=s, options=HardOptions.town()) for s in TOWN_SEEDS
    )


def _union(b: Building) -> shapely.Geometry:
    return shapely.unary_union([shapely.Polygon(blk.footprint_enu_m) for blk in b.blocks])


def _exterior(b: Building) -> shapely.Polygon:
    """Seen from above with any yard filled in (an arch's pillars, rounded apart from its
    deck by millimetres, leave no vertices of their own)."""
    shape = _union(b)
    assert isinstance(shape, shapely.Polygon), b.name
    return orient(shapely.Polygon(shape.exterior.coords).simplify(0.02))  # counter-clockwise


def _hsv(rgb: tuple[int, int, int]) -> tuple[float, float, float]:
    """Hue in degrees, saturation and value in 0..255 (as the vision code counts them)."""
    h, s, v = colorsys.rgb_to_hsv(*(c / 255.0 for c in rgb))
    return 360.0 * h, 255.0 * s, 255.0 * v


def _top(b: Building) -> float:
    return max(k.top_m for k in b.blocks)


# --------------------------------------------------------------------------- old scenes


@pytest.mark.parametrize(("options", "seed"), sorted(OLD_SCENES))
def test_scenes_without_the_town_classes_are_what_they_were(options: str, seed: int) -> None:
    scene, _ = generate_hard_scene_with_info(seed=seed, options=OLD_OPTIONS[options])
    digest = hashlib.sha256(dump_scene(scene).encode()).hexdigest()
    assert digest == OLD_SCENES[(options, seed)]


def test_the_town_knobs_are_off_by_default_and_off_means_no_draw() -> None:
    default = HardOptions()
    for name in TOWN_KNOBS:
        assert getattr(default, name) == 0.0, name
    # a knob at 0 draws nothing: the scene and its info are those of the default options
    for seed in range(40):
        plain, info = generate_hard_scene_with_info(seed=seed)
        assert info.classes == () and info.hole_decoy is None and info.towers == ()
        assert "--town" not in plain.description
        assert info.decoys == tuple(
            n for n in (info.mirror_decoy, info.scaled_decoy, info.near_decoy) if n
        )


def test_the_town_preset() -> None:
    town = HardOptions.town()
    assert all(getattr(town, name) > 0.0 for name in TOWN_KNOBS)
    assert town.home_overhang_p > 0.0  # home under a deck is a town class too
    assert hard_command(5, town) == "uavtool scene random --hard --town --seed 5"
    changed = HardOptions(**{**_as_dict(town), "dense_p": 0.5})  # type: ignore[arg-type]
    assert "--town" not in hard_command(5, changed)
    moved = HardOptions(**{**_as_dict(town), "random_home": True})  # type: ignore[arg-type]
    assert hard_command(5, moved) == ("uavtool scene random --hard --town --seed 5 --random-home")


def _as_dict(o: HardOptions) -> dict[str, object]:
    return {f.name: getattr(o, f.name) for f in fields(o)}


# --------------------------------------------------------------------------- every town scene


def test_every_town_scene_is_valid_apart_and_quick() -> None:
    for seed in (1, 50, 100, 150, 200):
        t0 = time.perf_counter()
        generate_hard_scene_with_info(seed=seed, options=HardOptions.town())
        assert time.perf_counter() - t0 < 2.0, seed
    home = shapely.Point(0.0, 0.0)
    for scene, info in _town():
        assert scene_from_dict(scene_to_dict(scene), source="x") == scene
        assert scene.ground_rgb == (128, 128, 128)
        assert 1 <= len(scene.buildings) <= 16
        assert scene.target == info.target
        margin = 4.0 if info.dense_gap_m is None else info.dense_gap_m
        shapes = {b.name: _union(b) for b in scene.buildings}
        for (a, sa), (b, sb) in itertools.combinations(shapes.items(), 2):
            assert sa.distance(sb) >= margin - 1e-6, (scene.name, a, b)
        # nothing over the target nor in its yard
        target = _exterior(scene.target_building)
        assert all(
            s.intersection(target).area == 0.0 for n, s in shapes.items() if n != info.target
        )
        for name, shape in shapes.items():
            if name not in (info.beside_home, info.over_home):
                assert shape.distance(home) >= 4.0 - 0.02, (scene.name, name)
        assert set(info.classes) <= set(TOWN_CLASSES)
        assert info.summary() in scene.description
        seed = int(scene.name.rsplit("-", 1)[1])
        assert scene.description.startswith(f"uavtool scene random --hard --town --seed {seed}:")


def test_each_town_class_turns_up_in_a_plausible_share() -> None:
    counts = dict.fromkeys(TOWN_CLASSES, 0)
    for _, info in _town():
        for c in info.classes:
            counts[c] += 1
    n = len(TOWN_SEEDS)
    share = {c: k / n for c, k in counts.items()}
    for c in (
        "grey",
        "darker shade",
        "hole decoy",
        "wing decoy",
        "courtyard target",
        "tower",
        "small target",
    ):
        assert 0.15 <= share[c] <= 0.45, (c, share[c])
    assert 0.12 <= share["dense"] <= 0.3, share["dense"]
    home = sum(i.home_tower is not None or i.over_home is not None for _, i in _town()) / n
    assert 0.2 <= home <= 0.45, home
    for c in ("darker shade of the target", "tower target", "home beside a tower"):
        assert share[c] >= 0.05, (c, share[c])


def test_same_seed_same_town_scene_and_a_random_home_keeps_the_buildings() -> None:
    town = HardOptions.town()
    moved_options = HardOptions(**{**_as_dict(town), "random_home": True})  # type: ignore[arg-type]
    for seed in (3, 4, 5):
        a, info = generate_hard_scene_with_info(seed=seed, options=town)
        b, _ = generate_hard_scene_with_info(seed=seed, options=town)
        assert dump_scene(a) == dump_scene(b)
        moved, moved_info = generate_hard_scene_with_info(seed=seed, options=moved_options)
        assert moved.buildings == a.buildings and moved_info == info


# --------------------------------------------------------------------------- colours


def test_grey_buildings_are_unsaturated_and_stand_out_from_the_ground() -> None:
    seen = 0
    for scene, info in _town():
        target_rgb = scene.target_building.color_rgb
        for name in info.grey:
            rgb = scene.building(name).color_rgb
            _, sat, val = _hsv(rgb)
            assert sat < 70.0, (scene.name, name, rgb)
            assert abs(val - GROUND_V) >= 25.0, (scene.name, name, rgb)
            assert rgb != target_rgb and name != info.target
            seen += 1
    assert seen > 80


def test_darker_shades_share_a_hue_and_are_clearly_darker() -> None:
    of_target = 0
    for scene, info in _town():
        for name, brighter in info.darker:
            assert name != info.target and name not in info.grey
            h, s, v = _hsv(scene.building(name).color_rgb)
            bh, bs, bv = _hsv(scene.building(brighter).color_rgb)
            assert _hue_gap(h, bh) <= 5.0, (scene.name, name, brighter)
            assert s >= 70.0 and bs >= 70.0  # colours, not greys
            assert v <= bv - 50.0, (scene.name, name, v, bv)
            of_target += brighter == info.target
    assert of_target > 20


# --------------------------------------------------------------------------- decoys


def test_hole_decoys_are_the_target_with_a_yard_more_or_less() -> None:
    filled = cut = 0
    for scene, info in _town():
        if info.hole_decoy is None:
            continue
        target, decoy = scene.target_building, scene.building(info.hole_decoy)
        assert decoy.color_rgb == target.color_rgb
        assert _top(decoy) == _top(target)
        yards = [len(_union(b).interiors) for b in (target, decoy)]
        assert sorted(yards) == [0, 1], (scene.name, yards)
        assert _best_fit_m(_exterior(target), _exterior(decoy)) < 0.05, scene.name
        holed = decoy if yards[1] else target
        yard = shapely.Polygon(_union(holed).interiors[0])
        assert yard.area >= 3.0
        assert yard.exterior.distance(_exterior(holed).exterior) >= 1.2 - 0.02
        if yards[0]:
            filled += 1
            assert info.target_kind == "courtyard"
        else:
            cut += 1
            assert info.hole_decoy in info.courtyards
    assert filled > 10 and cut > 10


def test_wing_decoys_are_the_target_with_one_wing_shorter_or_gone() -> None:
    removed = shortened = 0
    for scene, info in _town():
        if info.wing_decoy is None:
            continue
        target, decoy = scene.target_building, scene.building(info.wing_decoy)
        assert decoy.color_rgb == target.color_rgb
        assert _top(decoy) == _top(target)
        t, d = _exterior(target), _exterior(decoy)
        assert d.area < t.area - 0.5, scene.name
        cut = _cut_off(t, d)
        assert cut is not None, scene.name  # the decoy lies in the target, the rest a box
        x0, y0, x1, y1 = cut.bounds
        length = max(x1 - x0, y1 - y0)
        if len(d.exterior.coords) < len(t.exterior.coords):
            removed += 1
        else:
            shortened += 1
            box = shapely.oriented_envelope(cut)
            sides = sorted(math.dist(p, q) for p, q in itertools.pairwise(box.exterior.coords[:3]))
            assert any(2.0 - 0.15 <= side <= 4.0 + 0.05 for side in sides)  # buffered 0.1 m
        assert length > 0.5
        assert len(_union(decoy).interiors) == len(_union(target).interiors)
    assert removed > 5 and shortened > 20


def _cut_off(target: shapely.Polygon, decoy: shapely.Polygon) -> shapely.Polygon | None:
    """What the target has and the decoy lacks, when the decoy (turned and moved so that one
    of its edges lies on one of the target's) fits inside the target and that is one box."""
    pt, pd = list(target.exterior.coords)[:-1], list(decoy.exterior.coords)[:-1]
    for i, j in itertools.product(range(len(pd)), range(len(pt))):
        (a0, a1), (b0, b1) = (pd[i], pd[(i + 1) % len(pd)]), (pt[j], pt[(j + 1) % len(pt)])
        turn = math.atan2(b1[1] - b0[1], b1[0] - b0[0]) - math.atan2(a1[1] - a0[1], a1[0] - a0[0])
        moved = affinity.rotate(decoy, turn, origin=a0, use_radians=True)
        ends = moved.exterior.coords[i], moved.exterior.coords[i + 1]
        for anchor, here in zip((b0, b1), ends, strict=True):
            fit = affinity.translate(moved, anchor[0] - here[0], anchor[1] - here[1])
            # centimetre rounding: a few square decimetres of sliver along the edges
            if fit.difference(target).area < 0.2:
                rest = target.buffer(-0.05, join_style="mitre").difference(fit.buffer(0.05))
                rest = max(getattr(rest, "geoms", [rest]), key=lambda g: g.area)
                if rest.area > 0.5 and shapely.oriented_envelope(rest).area < rest.area + 0.3:
                    return rest
    return None


def test_courtyard_targets_have_an_open_yard() -> None:
    count = 0
    for scene, info in _town():
        if info.target_kind != "courtyard":
            continue
        count += 1
        target = scene.target_building
        assert info.target_shape in ("rectangle", "L") and info.target in info.courtyards
        shape = _union(target)
        assert len(shape.interiors) == 1 and len(target.blocks) == 2
        yard = shapely.Polygon(shape.interiors[0])
        assert not yard.buffer(-1.2).is_empty  # at least 2.4 m across everywhere
        assert yard.exterior.distance(shape.exterior) >= 2.2 - 0.02  # walls
        assert len({(k.base_m, k.top_m) for k in target.blocks}) == 1
    assert count > 30


def test_yards_make_watertight_meshes_with_a_through_hole() -> None:
    checked = 0
    for scene, info in _town()[:60]:
        for name in info.courtyards:
            b = scene.building(name)
            mesh = building_mesh(b)
            assert mesh.is_watertight, (scene.name, name)
            assert mesh.euler_number == 0  # a solid ring: genus one
            area = sum(shapely.Polygon(k.footprint_enu_m).area for k in b.blocks)
            assert mesh.volume == pytest.approx(area * _top(b), rel=1e-4)
            checked += 1
    assert checked > 10


# --------------------------------------------------------------------------- sizes


def test_towers_are_30_to_60_m_and_the_rest_as_tall_as_ever() -> None:
    targets = 0
    for scene, info in _town():
        for b in scene.buildings:
            if b.name in info.towers:
                assert TOWER_M[0] <= _top(b) <= TOWER_M[1], (scene.name, b.name)
            else:
                assert _top(b) <= 25.0, (scene.name, b.name)
        targets += info.target in info.towers
    assert targets > 10


def test_home_beside_a_tower() -> None:
    count = 0
    for scene, info in _town():
        if info.home_tower is None:
            continue
        count += 1
        tower = scene.building(info.home_tower)
        assert info.home_tower in info.towers and info.beside_home == info.home_tower
        assert 1.0 <= _union(tower).distance(shapely.Point(0.0, 0.0)) <= 3.0
        assert info.over_home is None
    assert count > 15


def test_dense_blocks() -> None:
    count = 0
    for scene, info in _town():
        if info.dense_gap_m is None:
            assert len(scene.buildings) <= 9
            continue
        count += 1
        assert 12 <= len(scene.buildings) <= 16
        assert 2.0 <= info.dense_gap_m <= 3.0
        shapes = [_union(b) for b in scene.buildings]
        nearest = [min(a.distance(b) for b in shapes if b is not a) for a in shapes]
        assert min(nearest) >= info.dense_gap_m - 1e-6
        assert sorted(nearest)[len(nearest) // 2] < 6.0  # most stand close to a neighbour
    assert count > 20


def test_small_targets_are_3_to_5_m_across() -> None:
    count = 0
    for scene, info in _town():
        if not info.small_target:
            continue
        count += 1
        points = list(_exterior(scene.target_building).exterior.coords)
        across = max(math.dist(p, q) for p, q in itertools.combinations(points, 2))
        assert 3.0 <= across <= 5.0, (scene.name, across)
        assert info.target_kind == "plain"
    assert count > 20


# --------------------------------------------------------------------------- CLI


def test_cli_town(tmp_path: Path) -> None:
    out = tmp_path / "t.yaml"
    result = CliRunner().invoke(
        cli, ["scene", "random", "--hard", "--town", "--seed", "9", "-o", str(out)]
    )
    assert result.exit_code == 0, result.stderr
    scene, info = generate_hard_scene_with_info(seed=9, options=HardOptions.town())
    assert out.read_text() == dump_scene(scene)
    assert load_scene(out) == scene
    assert info.summary() in result.stdout
    result = CliRunner().invoke(
        cli,
        ["scene", "random", "--hard", "--town", "--seed", "9", "--buildings", "7",
         "--random-home", "-o", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert load_scene(out).description.startswith(
        "uavtool scene random --hard --town --seed 9 --buildings 7 --random-home: "
    )
    result = CliRunner().invoke(cli, ["scene", "random", "--town", "--seed", "9", "-o", str(out)])
    assert result.exit_code == 2 and "--town needs --hard" in result.stderr


# --------------------------------------------------------------------------- geometry


def test_plane_geometry_helpers() -> None:
    from uavtool.world.hard_geometry import inset_ring, rectilinear, ring_distance_m, star_centre

    square = ((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0))
    yard = inset_ring(square, (1.0, 2.0, 1.0, 3.0))
    assert yard is not None
    assert [c for p in yard for c in p] == pytest.approx([3.0, 1.0, 8.0, 1.0, 8.0, 5.0, 3.0, 5.0])
    assert inset_ring(square, (4.0, 1.0, 4.0, 1.0)) is None  # the yard would turn over
    far = tuple((x + 13.0, y + 4.0) for x, y in square)
    assert ring_distance_m(square, far) == pytest.approx(3.0)
    inner = ((2.0, 2.0), (3.0, 2.0), (3.0, 3.0))
    assert ring_distance_m(square, inner) == 0.0  # one inside the other
    assert rectilinear(square) and not rectilinear(inner)
    centre = star_centre(square)
    assert centre is not None and centre[1] == 3.0 and 3.0 <= centre[0] <= 7.0  # 3 m clear
    you = ((0, 0), (9, 0), (9, 9), (7, 9), (7, 2), (2, 2), (2, 9), (0, 9))
    assert star_centre([(float(x), float(y)) for x, y in you]) is None  # no point sees all
