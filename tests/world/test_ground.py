"""Ground areas and the ground texture: the scene format, the renderer, the collision model."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.world import SceneError, load_scene, render, scene_from_dict, scene_to_dict
from uavtool.world.ground import GroundArea, GroundTexture, TextureKind
from uavtool.world.ground_render import TEXTURE_BLOCK_PX, _shaded, texture_frame, texture_tiles
from uavtool.world.obstacles import scene_obstacles
from uavtool.world.reference import render_reference
from uavtool.world.scene import Scene, dump_scene, parse_scene

GROUND = """\
name: g
target: a
ground:
  color: [90, 120, 70]
  areas:
    - name: road
      color: [60, 60, 64]
      polygon: [[-40, -3], [40, -3], [40, 3], [-40, 3]]
    - name: lawn
      color: [70, 150, 60]
      polygon: [[-20, 8], [-5, 8], [-5, 20], [-12, 14], [-20, 20]]
  texture: {kind: grain, amplitude_dn: 10, scale_m: 0.3, seed: 5}
buildings:
  - name: a
    color: [200, 30, 30]
    blocks:
      - footprint: [[10, 10], [16, 10], [16, 15], [10, 15]]
        top_m: 6
"""
K = Intrinsics.from_hfov()
NADIR = CameraPose((0.0, 0.0, 40.0), 0.0, -90.0)


def _scene(text: str = GROUND) -> Scene:
    return parse_scene(text, source="g.yaml")


def _pixel(pose: CameraPose, east_m: float, north_m: float) -> tuple[int, int]:
    uv = project(np.array([[east_m, north_m, 0.0]]), pose, K)
    return round(float(uv[0, 0])), round(float(uv[0, 1]))


# --------------------------------------------------------------------------- the format


def test_areas_and_texture_load_and_round_trip() -> None:
    scene = _scene()
    assert [a.name for a in scene.ground_areas] == ["road", "lawn"]
    assert scene.ground_areas[1].color_rgb == (70, 150, 60)
    assert scene.ground_texture == GroundTexture(TextureKind.GRAIN, 10.0, 0.3, 5)
    assert [b.name for b in scene.buildings] == ["a"]  # areas are not buildings
    assert scene_from_dict(scene_to_dict(scene), source="x") == scene
    assert parse_scene(dump_scene(scene), source="x.yaml") == scene
    assert parse_scene(dump_scene(scene, suffix=".json"), source="x.json", suffix=".json") == scene
    assert scene_from_dict(json.loads(json.dumps(scene_to_dict(scene)))) == scene


def test_a_scene_without_them_is_written_as_before() -> None:
    paper = load_scene("paper")
    assert scene_to_dict(paper)["ground"] == {"color": [128, 128, 128]}
    assert paper.ground_areas == () and paper.ground_texture is None
    only_colour = _scene(
        GROUND.split("  areas:", maxsplit=1)[0] + GROUND.split("seed: 5}\n", maxsplit=1)[1]
    )
    assert only_colour.ground_areas == () and only_colour.ground_texture is None


def test_texture_defaults() -> None:
    text = GROUND.replace("{kind: grain, amplitude_dn: 10, scale_m: 0.3, seed: 5}", "{kind: noise}")
    assert _scene(text).ground_texture == GroundTexture(TextureKind.NOISE, 8.0, 0.5, 0)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[0, 0], [10, 0], [0, 10], [12, 12]]",
            "g.yaml:8: ground.areas[0].polygon: self-intersecting polygon",
        ),
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[-40, -3], [40, -3]]",
            "g.yaml:8: ground.areas[0].polygon: a polygon needs at least 3 vertices, got 2",
        ),
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[-40, -3], [40, .nan], [40, 3]]",
            "g.yaml:8: ground.areas[0].polygon[1][1]: expected a finite number, got nan",
        ),
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[-40, -3], [40, -3], [40, -3], [-40, 3]]",
            "g.yaml:8: ground.areas[0].polygon[2]: repeated vertex",
        ),
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[0, 0], [1, 1], [2, 2]]",
            "g.yaml:8: ground.areas[0].polygon: polygon has zero area",
        ),
        (
            "[[-40, -3], [40, -3], [40, 3], [-40, 3]]",
            "[[-40, -3], [40000, -3], [40, 3]]",
            "g.yaml:8: ground.areas[0].polygon[1]: more than 10000 m from home",
        ),
        (
            "      color: [60, 60, 64]",
            "      color: [60, 60, 300]",
            "g.yaml:7: ground.areas[0].color: expected [r, g, b] with integers 0-255, got "
            "[60, 60, 300]",
        ),
        (
            "    - name: lawn",
            "    - name: road",
            "g.yaml:9: ground.areas[1].name: duplicate area name 'road'",
        ),
        (
            "      polygon: [[-40",
            "      polgon: [[-40",
            "g.yaml:8: ground.areas[0].polgon: unknown key (did you mean 'polygon'?); "
            "allowed: name, color, polygon",
        ),
        (
            "kind: grain",
            "kind: sand",
            "g.yaml:12: ground.texture.kind: expected one of grain, noise, got 'sand'",
        ),
        (
            "amplitude_dn: 10",
            "amplitude_dn: 100",
            "g.yaml:12: ground.texture.amplitude_dn: must be in [0, 64] DN, got 100.0",
        ),
        (
            "scale_m: 0.3",
            "scale_m: 0",
            "g.yaml:12: ground.texture.scale_m: must be in [0.02, 50] m, got 0.0",
        ),
        (
            "seed: 5",
            "seed: -1",
            "g.yaml:12: ground.texture.seed: expected a whole number 0..4294967295, got -1",
        ),
        (
            "  texture: {",
            "  textur: {",
            "g.yaml:12: ground.textur: unknown key (did you mean "
            "'texture'?); allowed: color, areas, texture",
        ),
    ],
)
def test_errors_are_one_line_and_name_the_key(old: str, new: str, message: str) -> None:
    assert old in GROUND
    with pytest.raises(SceneError) as exc:
        _scene(GROUND.replace(old, new, 1))
    assert str(exc.value) == message
    assert "\n" not in str(exc.value)


# --------------------------------------------------------------------------- not buildings


def test_areas_are_no_obstacles() -> None:
    """The built-in vehicle's collision model holds the buildings' blocks only: it flies and
    lands on a lawn or a road as on bare ground."""
    scene = _scene()
    bare = replace(scene, ground_areas=(), ground_texture=None)
    assert scene_obstacles(scene) == scene_obstacles(bare)
    assert [p.name for p in scene_obstacles(scene)] == ["a"]


# --------------------------------------------------------------------------- the renderer


def test_an_area_is_drawn_where_it_lies_and_buildings_stand_over_it() -> None:
    scene = replace(_scene(), ground_texture=None)
    image = render(scene, NADIR, K)
    for (east, north), rgb in (
        ((0.0, 0.0), (60, 60, 64)),  # the road
        ((20.0, -1.0), (60, 60, 64)),
        ((-15.0, 12.0), (70, 150, 60)),  # the lawn
        ((-12.0, 18.0), (90, 120, 70)),  # the lawn's notch: bare ground
        ((0.0, -12.0), (90, 120, 70)),
    ):
        u, v = _pixel(NADIR, east, north)
        assert tuple(image[v, u]) == rgb, (east, north)
    # a later area is drawn over an earlier one, and a building over both
    crossing = GroundArea(
        "cross", (200, 200, 40), ((-2.0, -10.0), (2.0, -10.0), (2.0, 10.0), (-2.0, 10.0))
    )
    under = GroundArea("under", (40, 40, 200), ((9.0, 9.0), (17.0, 9.0), (17.0, 16.0), (9.0, 16.0)))
    image = render(replace(scene, ground_areas=(*scene.ground_areas, crossing, under)), NADIR, K)
    u, v = _pixel(NADIR, 0.0, 0.0)
    assert tuple(image[v, u]) == (200, 200, 40)
    u, v = _pixel(NADIR, 13.0, 12.5)
    assert tuple(image[v, u]) != (40, 40, 200)  # the roof of "a" (shaded red)
    assert image[v, u][0] > 150
    u, v = _pixel(NADIR, 9.5, 9.5)
    assert tuple(image[v, u]) == (40, 40, 200)


def test_the_reference_renderer_sees_the_same_ground() -> None:
    """Both paint buildings over the same background (the ground is compared here, with the
    building out of sight: the two differ on ties at a building's edges)."""
    scene = _scene()
    away = scene.buildings[0]
    block = away.blocks[0]
    far = replace(block, footprint_enu_m=tuple((x + 900.0, y) for x, y in block.footprint_enu_m))
    scene = replace(scene, buildings=(replace(away, blocks=(far,)),))
    for pose in (NADIR, CameraPose((-5.0, -30.0, 8.0), 20.0, -20.0)):
        assert np.array_equal(render(scene, pose, K), render_reference(scene, pose, K))


def test_the_texture_stays_on_the_ground_as_the_camera_moves() -> None:
    """Moving the camera east by a whole number of texture blocks' ground width moves the
    image left by those pixels: the texture is fixed in world metres, not in the image."""
    scene = replace(_scene(), ground_areas=(), buildings=_scene().buildings)
    far = CameraPose((-60.0, 0.0, 40.0), 0.0, -90.0)  # the building out of sight
    shift_px = 4 * TEXTURE_BLOCK_PX
    metres_per_px = 40.0 / K.fx_px
    moved = CameraPose((-60.0 + shift_px * metres_per_px, 0.0, 40.0), 0.0, -90.0)
    a, b = render(scene, far, K), render(scene, moved, K)
    same = np.all(a[:, shift_px:] == b[:, :-shift_px], axis=2)
    assert same.mean() > 0.98  # cell edges exactly on a block's centre may fall either way
    assert not np.array_equal(a, b)


def test_the_texture_is_seeded_bounded_and_the_same_every_time() -> None:
    scene = _scene()
    flat = replace(scene, ground_texture=None, ground_areas=())
    textured = replace(flat, ground_texture=scene.ground_texture)
    pose = CameraPose((-60.0, 0.0, 40.0), 0.0, -90.0)
    a = render(textured, pose, K)
    texture_tiles.cache_clear()
    assert np.array_equal(a, render(textured, pose, K))
    ground = np.array([90, 120, 70])
    diff = a.astype(int) - ground
    assert np.abs(diff).max() <= 10  # amplitude_dn
    assert np.abs(diff).mean() > 1.0  # and visibly there
    assert (diff[:, :, 0] == diff[:, :, 1]).all()  # the same offset on every channel
    assert scene.ground_texture is not None
    other = replace(textured, ground_texture=replace(scene.ground_texture, seed=6))
    assert not np.array_equal(a, render(other, pose, K))
    assert np.array_equal(render(flat, pose, K), np.broadcast_to(ground, a.shape))


def test_far_ground_is_smoothed_and_the_sky_untouched() -> None:
    scene = replace(_scene(), ground_areas=())
    pose = CameraPose((-60.0, -60.0, 2.0), 0.0, 0.0)  # looking at the horizon
    image = render(scene, pose, K).astype(int)
    sky = np.array([205, 218, 232])
    assert (image[:200] == sky).all()
    ground = image[240:] - np.array([90, 120, 70])
    near, far = np.abs(ground[-40:]).mean(), np.abs(ground[:4]).mean()
    assert far < near  # box-filtered levels: far cells are averaged


def test_a_camera_under_the_ground_sees_no_texture_or_areas() -> None:
    scene = _scene()
    under = CameraPose((0.0, 0.0, -1.0), 0.0, 90.0)
    image = render(scene, under, K)
    assert image.shape == (480, 640, 3)


def test_blocks_are_spread_by_copying_only() -> None:
    """OpenCV's nearest resize by a whole factor is a copy: what numpy's repeat gives."""
    scene = _scene()
    assert scene.ground_texture is not None
    frame = texture_frame(scene.ground_texture, NADIR, K, first_row=0)
    assert frame is not None
    k = frame.block
    small = np.take(_shaded((90, 120, 70)), frame.offsets_dn + 64)
    expected = np.repeat(np.repeat(small, k, axis=0), k, axis=1)
    assert np.array_equal(frame.paint((90, 120, 70), slice(0, 480), slice(0, 640)), expected)
    assert np.array_equal(
        frame.paint((90, 120, 70), slice(7, 99), slice(3, 101)), expected[7:99, 3:101]
    )
