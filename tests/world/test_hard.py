"""The seeded generator of hard scenes, its CLI, and the hand-written hard built-in scenes."""

from __future__ import annotations

import colorsys
import hashlib
import itertools
import math
from functools import cache
from pathlib import Path

import pytest
import shapely
from click.testing import CliRunner
from shapely import affinity

from tests.world.bodies import body_count
from uavtool.cli import cli
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.world import SceneError, load_scene
from uavtool.world.hard import (
    HardOptions,
    HardSceneInfo,
    generate_hard_scene,
    generate_hard_scene_with_info,
    hard_command,
)
from uavtool.world.scene import Building, Scene, dump_scene, scene_from_dict, scene_to_dict

SEEDS = range(200)
# The file for seed 7; a change means old seeds no longer give old scenes.
GOLDEN_SEED7_SHA256 = "2e768e1adc42e33ba242ecf9b21e60edd2f6f0e116083003a89a0e17476e8c95"
# half-extents of the nadir view from 45 m with a 60° x 45° camera (640 x 480)
OVERVIEW_HALF_E_M, OVERVIEW_HALF_N_M = 26.0, 19.5


@cache
def _scenes() -> tuple[tuple[Scene, HardSceneInfo], ...]:
    return tuple(generate_hard_scene_with_info(seed=s) for s in SEEDS)


def _union(b: Building) -> shapely.Geometry:
    return shapely.unary_union([shapely.Polygon(blk.footprint_enu_m) for blk in b.blocks])


def _outline(b: Building) -> shapely.Polygon:
    """Seen from above: every generated building has one block whose footprint holds all."""
    widest = max(b.blocks, key=lambda k: shapely.Polygon(k.footprint_enu_m).area)
    return shapely.Polygon(widest.footprint_enu_m)


def _best_fit_m(a: shapely.Polygon, b: shapely.Polygon) -> float:
    """Hausdorff distance of ``a`` turned and moved onto ``b`` (no reflection), metres:
    every edge of ``a`` is tried against every edge of ``b``, both ways round."""
    ca, cb = a.centroid, b.centroid
    pa, pb = list(a.exterior.coords)[:-1], list(b.exterior.coords)[:-1]
    best = math.inf
    for i in range(len(pa)):
        (x0, y0), (x1, y1) = pa[i], pa[(i + 1) % len(pa)]
        ha = math.atan2(y1 - y0, x1 - x0)
        for j in range(len(pb)):
            (u0, v0), (u1, v1) = pb[j], pb[(j + 1) % len(pb)]
            turn = math.degrees(math.atan2(v1 - v0, u1 - u0) - ha)
            for extra in (0.0, 180.0):
                moved = affinity.rotate(a, turn + extra, origin=ca)
                moved = affinity.translate(moved, cb.x - ca.x, cb.y - ca.y)
                best = min(best, moved.hausdorff_distance(b))
    return best


def _mirrored(p: shapely.Polygon) -> shapely.Polygon:
    return shapely.Polygon(affinity.scale(p, xfact=-1.0, origin="centroid").exterior.coords[::-1])


def _hue_deg(rgb: tuple[int, int, int]) -> float:
    return 360.0 * colorsys.rgb_to_hsv(*(c / 255.0 for c in rgb))[0]


def _hue_gap(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def _has_tunnel(b: Building) -> bool:
    """A raised block resting on at least two blocks, with open space under part of it."""
    for top in b.blocks:
        if top.base_m <= 0.0:
            continue
        deck = shapely.Polygon(top.footprint_enu_m)
        under = [
            shapely.Polygon(k.footprint_enu_m)
            for k in b.blocks
            if k.top_m == top.base_m
            and shapely.Polygon(k.footprint_enu_m).intersection(deck).area > 0.1
        ]
        if len(under) >= 2 and deck.difference(shapely.unary_union(under)).area > 1.0:
            return True
    return False


# --------------------------------------------------------------------------- determinism


def test_same_seed_same_scene_and_file() -> None:
    a = generate_hard_scene(seed=7)
    assert scene_to_dict(a) == scene_to_dict(generate_hard_scene(seed=7))
    assert scene_to_dict(a) != scene_to_dict(generate_hard_scene(seed=8))
    assert hashlib.sha256(dump_scene(a).encode()).hexdigest() == GOLDEN_SEED7_SHA256
    dumps = {dump_scene(s) for s, _ in _scenes()}
    assert len(dumps) == len(SEEDS)


def test_description_is_the_command() -> None:
    scene, info = generate_hard_scene_with_info(seed=12)
    assert scene.description.startswith("uavtool scene random --hard --seed 12: target ")
    assert info.summary() in scene.description
    options = HardOptions(min_buildings=6, max_buildings=6, spread_m=40.0, home_overhang_p=1.0)
    assert hard_command(3, options) == (
        "uavtool scene random --hard --seed 3 --buildings 6 --spread 40 --overhang"
    )
    assert hard_command(3, HardOptions(mirror_decoy_p=1.0)).endswith(
        "--seed 3 (HardOptions: mirror_decoy_p=1)"
    )
    assert hard_command(3, HardOptions(random_home=True)).endswith("--seed 3 --random-home")


def test_a_random_home_moves_and_turns_home_and_keeps_the_buildings() -> None:
    """`--random-home`: the seed's own buildings around a home anywhere within 60° of the
    equator, the vehicle facing any way; drawn last, so the rest of the scene is the same."""
    homes = []
    for seed in SEEDS:
        plain, info = generate_hard_scene_with_info(seed=seed)
        moved, moved_info = generate_hard_scene_with_info(
            seed=seed, options=HardOptions(random_home=True)
        )
        assert moved.buildings == plain.buildings and moved_info == info
        assert -60.0 <= moved.home.lat_deg <= 60.0 and -180.0 <= moved.home.lon_deg <= 180.0
        assert 0.0 <= moved.home_heading_deg < 360.0
        homes.append((moved.home.lat_deg, moved.home.lon_deg, moved.home_heading_deg))
    assert len(set(homes)) == len(SEEDS)
    headings = sorted(h for _, _, h in homes)
    assert headings[0] < 90.0 and headings[-1] > 270.0  # spread all round


def test_anywhere_puts_home_anywhere_to_85_degrees_and_a_third_across_the_date_line() -> None:
    """`--anywhere`: the seed's own buildings around a home to 85° of latitude, a third of
    them within the spread of the 180th meridian, so the town straddles it; drawn last."""
    lats, straddling = [], 0
    for seed in range(1, 61):
        plain, info = generate_hard_scene_with_info(seed=seed)
        moved, moved_info = generate_hard_scene_with_info(
            seed=seed, options=HardOptions(anywhere=True)
        )
        assert moved.buildings == plain.buildings and moved_info == info
        assert -85.0 <= moved.home.lat_deg <= 85.0 and -180.0 <= moved.home.lon_deg <= 180.0
        assert 0.0 <= moved.home_heading_deg < 360.0
        to_line = enu_from_geo(moved.home, GeoPoint(moved.home.lat_deg, 180.0, 0.0))[0]
        straddling += abs(to_line) <= HardOptions().spread_m + 1e-6
        lats.append(moved.home.lat_deg)
        assert "--anywhere" in moved.description
    assert 10 <= straddling <= 30  # a third of 60, give or take
    assert min(lats) < -60.0 and max(lats) > 60.0  # past --random-home's 60 degrees


# --------------------------------------------------------------------------- every scene


def test_every_scene_is_valid_tall_enough_and_apart() -> None:
    for scene, info in _scenes():
        assert scene_from_dict(scene_to_dict(scene), source="x") == scene
        assert 5 <= len(scene.buildings) <= 8
        assert scene.target == info.target
        for b in scene.buildings:
            assert 3.0 <= max(k.top_m for k in b.blocks) <= 25.0, (scene.name, b.name)
            assert all(0.0 <= k.base_m < k.top_m <= 25.0 for k in b.blocks)
            # every block's footprint is inside the building's outline: nothing sticks out
            assert _union(b).difference(_outline(b)).area < 0.05
        shapes = [_union(b) for b in scene.buildings]
        for a, b in itertools.combinations(shapes, 2):
            assert a.distance(b) >= 4.0 - 1e-6, scene.name
        home = shapely.Point(0.0, 0.0)
        near_home = {info.beside_home, info.over_home}
        for b, shape in zip(scene.buildings, shapes, strict=True):
            if b.name not in near_home:
                assert shape.distance(home) >= 4.0 - 0.02, (scene.name, b.name)


def test_colours_differ_in_hue_except_the_mirror_decoy() -> None:
    for scene, info in _scenes():
        hues = {b.name: _hue_deg(b.color_rgb) for b in scene.buildings}
        others = [h for n, h in hues.items() if n != info.mirror_decoy]
        for a, b in itertools.combinations(others, 2):
            assert _hue_gap(a, b) >= 40.0, scene.name
        if info.mirror_decoy is not None:
            gap = _hue_gap(hues[info.mirror_decoy], hues[info.target])
            assert 9.0 <= gap <= 21.0, scene.name
            rest = [_hue_gap(hues[info.mirror_decoy], h) for n, h in hues.items()]
            assert min(r for r, n in zip(rest, hues, strict=True) if n != info.mirror_decoy) == gap


def test_stepped_towers_shrink_upwards() -> None:
    count = 0
    for scene, info in _scenes():
        for name in info.stepped:
            tiers = sorted(scene.building(name).blocks, key=lambda k: k.base_m)
            assert len(tiers) in (2, 3)
            count += 1
            assert tiers[0].base_m == 0.0
            for low, high in itertools.pairwise(tiers):
                assert high.base_m == low.top_m
                inner, outer = (
                    shapely.Polygon(high.footprint_enu_m),
                    shapely.Polygon(low.footprint_enu_m),
                )
                assert inner.area < 0.7 * outer.area
                assert inner.difference(outer).area < 0.01
    assert count > 100


def test_every_kind_of_hard_case_turns_up() -> None:
    infos = [info for _, info in _scenes()]
    assert sum(i.mirror_decoy is not None for i in infos) > 60
    assert sum(i.scaled_decoy is not None for i in infos) > 40
    assert sum(i.near_decoy is not None for i in infos) > 40
    assert sum(i.beside_home is not None for i in infos) > 30
    assert sum(i.target_kind == "arch" for i in infos) > 20
    assert sum(i.target_kind == "stepped" for i in infos) > 20
    assert sum(bool(set(i.arches) - {i.target, *i.decoys}) for i in infos) > 20
    assert len({i.target_shape for i in infos}) == 8
    assert all(i.over_home is None for i in infos)  # off by default


def test_arches_have_tunnels() -> None:
    for scene, info in _scenes():
        for b in scene.buildings:
            assert _has_tunnel(b) == (b.name in info.arches), (scene.name, b.name)


def test_buildings_spread_past_one_overview() -> None:
    outside = 0
    for scene, _ in _scenes():
        for b in scene.buildings:
            minx, miny, maxx, maxy = _union(b).bounds
            if max(-minx, maxx) > OVERVIEW_HALF_E_M or max(-miny, maxy) > OVERVIEW_HALF_N_M:
                outside += 1
                break
    assert outside > 150


def test_home_beside_a_building() -> None:
    for scene, info in _scenes():
        if info.beside_home is not None:
            d = _union(scene.building(info.beside_home)).distance(shapely.Point(0.0, 0.0))
            assert 1.0 <= d <= 3.0, scene.name


# --------------------------------------------------------------------------- decoys


def test_mirror_decoy_is_a_mirror_image_not_a_turned_copy() -> None:
    checked = 0
    for scene, info in _scenes()[:80]:
        if info.mirror_decoy is None:
            continue
        target = _outline(scene.target_building)
        decoy = _outline(scene.building(info.mirror_decoy))
        assert decoy.area == pytest.approx(target.area, rel=0.01)
        assert _best_fit_m(_mirrored(target), decoy) < 0.05, scene.name
        x0, y0, x1, y1 = target.bounds  # the target is chiral: 10 % of its size (not turned)
        assert _best_fit_m(target, decoy) > 0.1 * max(x1 - x0, y1 - y0) / math.sqrt(2.0) - 0.05
        checked += 1
    assert checked > 20


def test_scaled_decoy_is_a_turned_scaled_copy() -> None:
    checked = 0
    for scene, info in _scenes()[:80]:
        if info.scaled_decoy is None:
            continue
        target = _outline(scene.target_building)
        decoy = _outline(scene.building(info.scaled_decoy))
        scale = math.sqrt(decoy.area / target.area)
        assert 0.6 - 1e-3 <= scale <= 1.5 + 1e-3
        grown = affinity.scale(target, scale, scale, origin="centroid")
        assert _best_fit_m(grown, decoy) < 0.05, scene.name
        checked += 1
    assert checked > 20


def test_near_decoy_has_one_vertex_moved() -> None:
    checked = 0
    for scene, info in _scenes()[:80]:
        if info.near_decoy is None:
            continue
        target = _outline(scene.target_building)
        decoy = _outline(scene.building(info.near_decoy))
        t, d = list(target.exterior.coords)[:-1], list(decoy.exterior.coords)[:-1]
        assert len(t) == len(d)
        size = max(math.dist(p, q) for p, q in itertools.combinations(t, 2))
        # some alignment puts all vertices but one on the target's; that one moved 10-25 %
        assert _moved_one(t, d, size), scene.name
        checked += 1
    assert checked > 20


def _moved_one(t: list[tuple[float, float]], d: list[tuple[float, float]], size: float) -> bool:
    n = len(t)
    for shift in range(n):
        for e in range(n):
            a0, a1 = t[e], t[(e + 1) % n]
            b0, b1 = d[(e + shift) % n], d[(e + 1 + shift) % n]
            turn = math.atan2(b1[1] - b0[1], b1[0] - b0[0]) - math.atan2(
                a1[1] - a0[1], a1[0] - a0[0]
            )
            c, s = math.cos(turn), math.sin(turn)
            moved = [
                (
                    b0[0] + c * (x - a0[0]) - s * (y - a0[1]),
                    b0[1] + s * (x - a0[0]) + c * (y - a0[1]),
                )
                for x, y in t
            ]
            gaps = [math.dist(moved[i], d[(i + shift) % n]) for i in range(n)]
            off = [g for g in gaps if g > 0.05]
            if len(off) == 1 and 0.1 * size / math.sqrt(2.0) - 0.05 <= off[0] <= 0.25 * size + 0.05:
                return True
    return False


# --------------------------------------------------------------------------- options


def test_home_under_an_arch() -> None:
    options = HardOptions(home_overhang_p=1.0)
    home = shapely.Point(0.0, 0.0)
    for seed in range(30):
        scene, info = generate_hard_scene_with_info(seed=seed, options=options)
        assert info.over_home is not None and info.beside_home is None
        arch = scene.building(info.over_home)
        raised = [k for k in arch.blocks if k.base_m > 0.0]
        assert len(raised) == 1 and 5.0 <= raised[0].base_m <= 7.0
        assert shapely.Polygon(raised[0].footprint_enu_m).contains(home)
        pillars = shapely.unary_union(
            [shapely.Polygon(k.footprint_enu_m) for k in arch.blocks if k.base_m == 0.0]
        )
        assert pillars.distance(home) >= 1.5 - 0.02
        assert _has_tunnel(arch)


def test_options_shape_the_scene() -> None:
    options = HardOptions(
        min_buildings=12, max_buildings=12, spread_m=60.0, margin_m=6.0, min_height_m=10.0,
        max_height_m=12.0, mirror_decoy_p=1.0, near_decoy_p=1.0, scaled_decoy_p=1.0,
    )  # fmt: skip
    for seed in range(10):
        scene, info = generate_hard_scene_with_info(seed=seed, options=options)
        assert len(scene.buildings) == 12
        assert None not in (info.mirror_decoy, info.scaled_decoy)
        assert all(10.0 <= max(k.top_m for k in b.blocks) <= 12.0 for b in scene.buildings)
        shapes = [_union(b) for b in scene.buildings]
        assert min(a.distance(b) for a, b in itertools.combinations(shapes, 2)) >= 6.0 - 1e-6
    few = generate_hard_scene_with_info(
        seed=1, options=HardOptions(min_buildings=1, max_buildings=1)
    )
    assert len(few[0].buildings) == 1 and few[1].decoys == ()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"min_buildings": 0}, "buildings must satisfy"),
        ({"min_buildings": 9}, "buildings must satisfy"),
        ({"max_buildings": 17}, "buildings must satisfy"),
        ({"min_height_m": 30.0}, "heights must satisfy"),
        ({"spread_m": 1.0}, "spread must be"),
        ({"margin_m": -1.0}, "margin must be"),
        ({"mirror_decoy_p": 1.5}, "mirror_decoy_p is a probability"),
    ],
)
def test_bad_options_are_scene_errors(kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(SceneError, match=message):
        HardOptions(**kwargs)  # type: ignore[arg-type]


# --------------------------------------------------------------------------- CLI


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_cli_writes_a_hard_scene_that_loads_and_renders(tmp_path: Path) -> None:
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    code, out, err = _run("scene", "random", "--hard", "--seed", "3", "-o", str(a))
    assert code == 0, err
    assert "target" in out
    assert _run("scene", "random", "--hard", "--seed", "3", "-o", str(b))[0] == 0
    assert a.read_bytes() == b.read_bytes() == dump_scene(generate_hard_scene(seed=3)).encode()
    assert load_scene(a) == generate_hard_scene(seed=3)
    png = tmp_path / "a.png"
    code, _, err = _run(
        "scene", "render", str(a), "--pos", "0,0,45", "--size", "64x48", "-o", str(png)
    )
    assert code == 0, err
    assert png.stat().st_size > 0
    c = tmp_path / "c.json"
    code, _, err = _run(
        "scene", "random", "--hard", "--seed", "4", "--buildings", "6", "--spread", "50",
        "--overhang", "-o", str(c),
    )  # fmt: skip
    assert code == 0, err
    scene = load_scene(c)
    assert len(scene.buildings) == 6
    assert scene.description.startswith(
        "uavtool scene random --hard --seed 4 --buildings 6 --spread 50 --overhang: "
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--seed", "1", "--spread", "40"), "--spread needs --hard"),
        (("--seed", "1", "--overhang"), "--overhang needs --hard"),
        (("--seed", "1", "--random-home"), "--random-home needs --hard"),
        (("--hard", "--seed", "1", "--buildings", "40"), "--buildings must be in 1..16"),
        (("--hard", "--seed", "1", "--spread", "1"), "spread must be"),
        (("--hard", "--seed", "1", "--margin", "-1"), "margin must be"),
    ],
)
def test_cli_bad_input_is_one_line_and_exit_2(args: tuple[str, ...], message: str) -> None:
    code, _, err = _run("scene", "random", *args, "-o", "never.yaml")
    assert code == 2
    assert message in err
    assert err.startswith("uavtool: error: ")
    assert err.count("\n") == 1


# --------------------------------------------------------------------------- built-in scenes


def test_builtin_mirror_decoy_scene() -> None:
    scene = load_scene("mirror-decoy")
    red = _outline(scene.target_building)
    assert _best_fit_m(_mirrored(red), _outline(scene.building("crimson"))) < 0.02
    assert _best_fit_m(red, _outline(scene.building("crimson"))) > 0.5
    blue = _outline(scene.building("blue"))
    assert math.sqrt(blue.area / red.area) == pytest.approx(0.7, abs=0.01)
    assert _best_fit_m(affinity.scale(red, 0.7, 0.7), blue) < 0.02
    hues = {b.name: _hue_deg(b.color_rgb) for b in scene.buildings}
    assert 10.0 <= _hue_gap(hues["crimson"], hues["red"]) <= 20.0
    t = list(red.exterior.coords)[:-1]
    g = list(_outline(scene.building("green")).exterior.coords)[:-1]
    assert _moved_one(t, g, max(math.dist(p, q) for p, q in itertools.combinations(t, 2)))


def test_builtin_tall_spread_scene() -> None:
    scene = load_scene("tall-spread")
    tops = [max(k.top_m for k in b.blocks) for b in scene.buildings]
    assert min(tops) == 3.0 and max(tops) == 25.0
    bounds = [_union(b).bounds for b in scene.buildings]
    assert max(max(-x0, x1, -y0, y1) for x0, y0, x1, y1 in bounds) >= 33.0
    red = scene.target_building
    assert len(red.blocks) == 3 and max(k.top_m for k in red.blocks) == 24.0
    _, y0, x1, _ = _union(red).bounds
    assert x1 > OVERVIEW_HALF_E_M and y0 < -OVERVIEW_HALF_N_M  # partly outside the overview


def test_builtin_arch_scene() -> None:
    scene = load_scene("arch")
    assert _has_tunnel(scene.target_building)
    assert _union(scene.building("tower")).distance(shapely.Point(0.0, 0.0)) == 2.0
    red, yellow = _outline(scene.target_building), _outline(scene.building("yellow"))
    assert _best_fit_m(red, yellow) < 0.01  # same roof from above, no tunnel
    assert not _has_tunnel(scene.building("yellow"))


def test_hard_buildings_make_watertight_meshes() -> None:
    from uavtool.world import building_mesh

    buildings = [
        b for n in ("mirror-decoy", "tall-spread", "arch") for b in load_scene(n).buildings
    ]
    for scene, info in _scenes()[:40]:
        buildings += [scene.building(n) for n in {info.target, *info.arches, *info.stepped}]
    for b in buildings:
        mesh = building_mesh(b)
        assert mesh.is_watertight, b.name
        assert body_count(mesh) == 1  # touching blocks are merged
        volume = sum(
            shapely.Polygon(k.footprint_enu_m).area * (k.top_m - k.base_m) for k in b.blocks
        )
        assert mesh.volume == pytest.approx(volume, rel=1e-4)
