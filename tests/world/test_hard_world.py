"""The world classes of hard scenes: light, ground colour, ground areas, texture, near shapes."""

from __future__ import annotations

import colorsys
import hashlib
from dataclasses import fields, replace
from functools import cache
from pathlib import Path

import pytest
import shapely
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.sweep.scenes import load_source_scene
from uavtool.sweep.spec import SceneKind, SceneSource
from uavtool.vision.params import VectorizeParams
from uavtool.world import load_scene
from uavtool.world.hard import (
    WORLD_KNOBS,
    HardOptions,
    HardSceneInfo,
    generate_hard_scene,
    generate_hard_scene_with_info,
    hard_command,
)
from uavtool.world.hard_world import NEAR_CLASSES
from uavtool.world.scene import Building, Scene, dump_scene, scene_from_dict, scene_to_dict

SEEDS = range(1, 61)
WORLD = HardOptions().with_world()
TOWN_WORLD = HardOptions.town().with_world()


@cache
def _pairs(town: bool) -> tuple[tuple[Scene, HardSceneInfo, Scene, HardSceneInfo], ...]:
    base = HardOptions.town() if town else HardOptions()
    return tuple(
        (
            *generate_hard_scene_with_info(seed=s, options=base),
            *generate_hard_scene_with_info(seed=s, options=base.with_world()),
        )
        for s in SEEDS
    )


def _outline(b: Building) -> shapely.Geometry:
    return shapely.unary_union([shapely.Polygon(k.footprint_enu_m) for k in b.blocks])


def _hue(rgb: tuple[int, int, int]) -> float:
    return 360.0 * colorsys.rgb_to_hsv(*(c / 255.0 for c in rgb))[0]


def _hue_gap(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def test_the_knobs_are_off_by_default() -> None:
    default = HardOptions()
    assert all(getattr(default, f) is False for f in WORLD_KNOBS)
    assert all(getattr(HardOptions.town(), f) is False for f in WORLD_KNOBS)
    assert {f.name for f in fields(HardOptions)} >= set(WORLD_KNOBS)


@pytest.mark.parametrize("town", [False, True])
def test_they_are_drawn_last_so_the_seed_keeps_its_buildings_and_home(town: bool) -> None:
    for plain, info, world, world_info in _pairs(town):
        n = len(plain.buildings)
        assert world.buildings[:n] == plain.buildings
        assert (world.home, world.home_heading_deg, world.target) == (
            plain.home,
            plain.home_heading_deg,
            plain.target,
        )
        assert replace(world_info, near_shapes=(), world=()) == info
        assert [b.name for b in world.buildings[n:]] == [n for n, _ in world_info.near_shapes]


def test_the_same_seed_gives_the_same_file() -> None:
    a = dump_scene(generate_hard_scene(seed=9, options=TOWN_WORLD))
    assert a == dump_scene(generate_hard_scene(seed=9, options=TOWN_WORLD))
    assert (
        hashlib.sha256(a.encode()).hexdigest()
        != hashlib.sha256(
            dump_scene(generate_hard_scene(seed=10, options=TOWN_WORLD)).encode()
        ).hexdigest()
    )
    scene = generate_hard_scene(seed=9, options=TOWN_WORLD)
    assert scene_from_dict(scene_to_dict(scene), source="x") == scene


def test_light_and_texture_in_their_ranges() -> None:
    elevations, azimuths = [], []
    for *_, world, _info in _pairs(False):
        light = world.lighting
        assert 5.0 <= light.sun_elevation_deg <= 90.0
        assert 0.0 <= light.sun_azimuth_deg < 360.0
        assert 0.15 <= light.ambient <= 0.8
        elevations.append(light.sun_elevation_deg)
        azimuths.append(light.sun_azimuth_deg)
        texture = world.ground_texture
        assert texture is not None and 4.0 <= texture.amplitude_dn <= 14.0
    assert min(elevations) < 20.0 and max(elevations) > 70.0
    assert min(azimuths) < 60.0 and max(azimuths) > 300.0


@pytest.mark.parametrize("town", [False, True])
def test_the_ground_is_any_colour_but_the_targets_and_no_roofs(town: bool) -> None:
    tolerance = VectorizeParams().hue_tolerance_deg
    greens = browns = with_areas = 0
    for *_, world, _info in _pairs(town):
        target_hue = _hue(world.target_building.color_rgb)
        grounds = [world.ground_rgb, *(a.color_rgb for a in world.ground_areas)]
        for rgb in grounds:
            assert _hue_gap(_hue(rgb), target_hue) >= tolerance, world.name
            for b in world.buildings:
                assert max(abs(x - y) for x, y in zip(rgb, b.color_rgb, strict=True)) >= 40
        h, s, _ = colorsys.rgb_to_hsv(*(c / 255.0 for c in world.ground_rgb))
        greens += 75.0 <= 360.0 * h <= 140.0 and s >= 0.35
        browns += 20.0 <= 360.0 * h <= 45.0 and s >= 0.35
        assert len(world.ground_areas) <= 6
        with_areas += len(world.ground_areas) >= 2  # an area with no fair colour is left out
    assert greens >= 5 and browns >= 5
    assert with_areas >= 0.9 * len(SEEDS)


def test_near_shapes_are_the_targets_colour_and_height_and_almost_its_outline() -> None:
    seen: set[str] = set()
    for seed in range(1, 121):
        world, info = generate_hard_scene_with_info(seed=seed, options=TOWN_WORLD)
        target = world.target_building
        top = max(k.top_m for k in target.blocks)
        outline = shapely.Polygon(_outline(target).exterior)
        assert 1 <= len(info.near_shapes) <= 2, seed
        for name, kind in info.near_shapes:
            assert kind in NEAR_CLASSES
            seen.add(kind)
            b = world.building(name)
            assert name != world.target and name in info.decoys
            assert b.color_rgb == target.color_rgb
            assert [(k.base_m, k.top_m) for k in b.blocks] == [(0.0, top)]
            near = shapely.Polygon(b.blocks[0].footprint_enu_m)
            ratio = near.area / outline.area
            assert 0.55 <= ratio <= 1.15, (seed, kind, ratio)
            assert abs(ratio - 1.0) > 0.004 or kind in ("chamfer", "notch"), (seed, kind)
            for other in world.buildings:
                if other.name != name:
                    assert near.distance(_outline(other)) >= HardOptions.town().margin_m - 0.02
            assert near.distance(shapely.Point(0.0, 0.0)) >= 4.0 - 0.02
    assert seen == set(NEAR_CLASSES)


def test_the_command_names_the_knobs() -> None:
    assert hard_command(3, WORLD) == "uavtool scene random --hard --seed 3 --world"
    assert hard_command(3, TOWN_WORLD) == "uavtool scene random --hard --town --seed 3 --world"
    light = replace(HardOptions(), any_light=True, ground_texture=True)
    assert hard_command(3, light) == "uavtool scene random --hard --seed 3 --light --texture"
    assert "--world" in generate_hard_scene(seed=3, options=WORLD).description


def test_the_cli_writes_the_generated_scene(tmp_path: Path) -> None:
    out = tmp_path / "w.yaml"
    run = CliRunner().invoke(
        cli, ["scene", "random", "--hard", "--town", "--world", "--seed", "5", "-o", str(out)]
    )
    assert run.exit_code == 0, run.output
    assert load_scene(out) == generate_hard_scene(seed=5, options=TOWN_WORLD)
    one = tmp_path / "one.yaml"
    run = CliRunner().invoke(
        cli, ["scene", "random", "--hard", "--near-shapes", "--seed", "5", "-o", str(one)]
    )
    assert run.exit_code == 0, run.output
    assert load_scene(one) == generate_hard_scene(
        seed=5, options=replace(HardOptions(), near_shapes=True)
    )
    run = CliRunner().invoke(cli, ["scene", "random", "--texture", "--seed", "5", "-o", str(one)])
    assert run.exit_code == 2 and "--texture needs --hard" in run.output


def test_sweeps_take_the_knobs_as_generator_options() -> None:
    """A sweep spec's `hard = { seeds = [...], any_light = true, ... }`."""
    options = tuple(sorted(dict.fromkeys(WORLD_KNOBS, True).items()))
    source = SceneSource(SceneKind.HARD, seeds=(4,), options=options)
    assert load_source_scene(source, 4) == generate_hard_scene(seed=4, options=WORLD)


def test_the_grounds_hue_gap_is_the_vectorizers_hue_window() -> None:
    from uavtool.vision.params import VectorizeParams
    from uavtool.world.hard_world import GROUND_HUE_GAP_DEG

    assert VectorizeParams().hue_tolerance_deg == GROUND_HUE_GAP_DEG
