"""The renderer: projection geometry, depth order, through-holes, clipping, determinism."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.world import Block, Building, Scene, load_scene, render
from uavtool.world.generator import generate_scene
from uavtool.world.raster import NEAR_M, prepare, project_faces, shade
from uavtool.world.reference import render_reference
from uavtool.world.render import render_packed, rgb_from_packed

K = Intrinsics.from_hfov()
SMALL = Intrinsics.from_hfov(width_px=160, height_px=120)
NADIR_45 = CameraPose((0.0, 0.0, 45.0), 0.0, -90.0)
FRONT_OF_RED = CameraPose((8.75, -32.0, 1.2), 0.0, 0.0)  # looking north along the wing's tunnel


def _box(
    name: str, rgb: tuple[int, int, int], x0: float, y0: float, x1: float, y1: float, top: float
) -> Building:
    return Building(name, rgb, (Block(((x0, y0), (x1, y0), (x1, y1), (x0, y1)), 0.0, top),))


def _scene(*buildings: Building) -> Scene:
    return load_scene("paper").__class__(
        name="t",
        home=load_scene("paper").home,
        home_heading_deg=0.0,
        buildings=buildings,
        target=buildings[0].name,
    )


def _roof_rgb(scene: Scene, name: str) -> tuple[int, int, int]:
    return shade(scene.building(name).color_rgb, (0.0, 0.0, 1.0), scene)


def _wall_rgb(scene: Scene, name: str, normal: tuple[float, float, float]) -> tuple[int, int, int]:
    return shade(scene.building(name).color_rgb, normal, scene)


def test_image_shape_type_and_background() -> None:
    scene = _scene(_box("a", (200, 30, 30), 100, 100, 101, 101, 1))
    img = render(scene, NADIR_45, K)
    assert img.shape == (480, 640, 3)
    assert img.dtype == np.uint8
    assert (img == scene.ground_rgb).all()  # the building is out of view
    level = render(scene, CameraPose((0, 0, 2), 90, 0), K)
    assert tuple(level[0, 0]) == scene.sky_rgb
    assert tuple(level[-1, 0]) == scene.ground_rgb
    assert tuple(level[239, 0]) == scene.sky_rgb  # the horizon runs through the principal point
    assert tuple(level[240, 0]) == scene.ground_rgb


@pytest.mark.parametrize(
    "pose",
    [NADIR_45, CameraPose((-3.0, 2.0, 30.0), 37.0, -70.0), CameraPose((7.0, -25.0, 5.0), 5.0, 0.0)],
)
def test_known_point_lands_on_its_projected_pixel(pose: CameraPose) -> None:
    # a 0.5 m square pillar at (7.25, -4.25): its roof's pixels centre on the projected roof centre
    scene = _scene(_box("a", (200, 30, 30), 7.0, -4.5, 7.5, -4.0, 5.0))
    img = render(scene, pose, K)
    colour = (
        _roof_rgb(scene, "a") if pose.pitch_deg < -10 else _wall_rgb(scene, "a", (0.0, -1.0, 0.0))
    )
    vs, us = np.nonzero(np.all(img == colour, axis=2))
    assert us.size >= 4
    point = (7.25, -4.25, 5.0) if pose.pitch_deg < -10 else (7.25, -4.5, 2.5)
    u, v, _ = project(np.array([point]), pose, K)[0]
    assert abs(float(us.mean()) - u) <= 0.5
    assert abs(float(vs.mean()) - v) <= 0.5


def test_roof_edges_fall_between_the_right_columns() -> None:
    scene = _scene(_box("a", (200, 30, 30), -4, -3, 2, 1, 5))
    roof = np.all(render(scene, NADIR_45, K) == _roof_rgb(scene, "a"), axis=2)
    (u_east, v_north, _), (u_west, _, _) = project(
        np.array([[2.0, 1.0, 5.0], [-4.0, -3.0, 5.0]]), NADIR_45, K
    )
    cols = np.nonzero(roof[round(v_north) + 3])[0]
    # pixel i is covered when its centre is inside: edges lie within ½ px of the run's ends
    assert abs((cols.max() + 0.5) - u_east) <= 0.5
    assert abs((cols.min() - 0.5) - u_west) <= 0.5


def test_near_building_hides_far_one() -> None:
    near = _box("near", (200, 30, 30), -2, 10, 2, 11, 6)
    far = _box("far", (30, 30, 200), -12, 30, 12, 31, 10)
    scene = _scene(far, near)
    pose = CameraPose((0.0, 0.0, 2.0), 0.0, 0.0)
    img = render(scene, pose, K)
    centre = tuple(img[235, 319])
    assert centre == _wall_rgb(scene, "near", (0.0, -1.0, 0.0))
    u, v, _ = project(np.array([[8.0, 30.0, 3.0]]), pose, K)[0]  # beside the near one
    assert tuple(img[round(v), round(u)]) == _wall_rgb(scene, "far", (0.0, -1.0, 0.0))
    # the same from behind: now the other one is in front
    back = render(scene, CameraPose((0.0, 45.0, 2.0), 180.0, 0.0), K)
    assert tuple(back[235, 319]) == _wall_rgb(scene, "far", (0.0, 1.0, 0.0))


def _face_colours(scene: Scene, name: str) -> set[tuple[int, int, int]]:
    normals = prepare(scene).normals.tolist()
    return {shade(scene.building(name).color_rgb, (n[0], n[1], n[2]), scene) for n in normals}


def test_through_hole_shows_what_is_behind() -> None:
    scene = load_scene("paper")
    img = render(scene, FRONT_OF_RED, K)
    # above the wing's tunnel: red wall; in the tunnel: what lies behind, not red
    above = project(np.array([[8.75, -12.0, 3.5]]), FRONT_OF_RED, K)[0]
    inside = project(np.array([[8.75, -12.0, 0.6]]), FRONT_OF_RED, K)[0]
    assert tuple(img[round(above[1]), round(above[0])]) == _wall_rgb(scene, "red", (0.0, -1.0, 0.0))
    assert tuple(img[round(inside[1]), round(inside[0])]) not in _face_colours(scene, "red")
    # from the east, the blue building shows through the leg's tunnel
    pose = CameraPose((40.0, -6.25, 1.5), 270.0, 0.0)
    east = render(scene, pose, K)
    through = project(np.array([[15.0, -6.25, 1.0]]), pose, K)[0]
    assert tuple(east[round(through[1]), round(through[0])]) in _face_colours(scene, "blue")


POSES = [
    NADIR_45,
    CameraPose((11.0, -8.5, 20.0), 0.0, -90.0),
    FRONT_OF_RED,
    CameraPose((35.0, -6.0, 3.0), 270.0, 0.0),
    CameraPose((-25.0, -30.0, 20.0), 45.0, -30.0),
    CameraPose((10.0, -6.25, 1.5), 93.0, -5.0),  # inside the tunnel: faces cross the near plane
    CameraPose((16.0, -13.0, 8.0), 300.0, -35.0),  # close to the walls
]


def _near_a_building(scene: Scene, pose: CameraPose, reach_m: float) -> bool:
    """Whether the camera is inside a block or within ``reach_m`` of one."""
    import shapely

    e, n, u = pose.pos_enu_m
    return any(
        blk.base_m - reach_m <= u <= blk.top_m + reach_m
        and shapely.Polygon(blk.footprint_enu_m).distance(shapely.Point(e, n)) < reach_m
        for b in scene.buildings
        for blk in b.blocks
    )


def _inside_a_building(scene: Scene, pose: CameraPose) -> bool:
    import shapely

    e, n, u = pose.pos_enu_m
    return any(
        blk.base_m <= u <= blk.top_m
        and shapely.Polygon(blk.footprint_enu_m).covers(shapely.Point(e, n))
        for b in scene.buildings
        for blk in b.blocks
    )


def _assert_same_but_ties(scene: Scene, pose: CameraPose, intr: Intrinsics) -> None:
    """Fast and reference frames agree except where a pixel centre lies on a face edge."""
    fast = render(scene, pose, intr)
    ref = render_reference(scene, pose, intr)
    rows, cols = np.nonzero(np.any(fast != ref, axis=2))
    assert rows.size <= 1e-3 * fast.shape[0] * fast.shape[1]
    faces = project_faces(prepare(scene), pose, intr, cull=False)
    for v, u in zip(rows.tolist(), cols.tolist(), strict=True):
        gap = min(_distance_to_edges(u, v, f.u_px, f.v_px) for f in faces)
        assert gap < 1e-6, (pose, (v, u), gap)


def _distance_to_edges(u: float, v: float, us: tuple[float, ...], vs: tuple[float, ...]) -> float:
    best = np.inf
    for k in range(len(us)):
        a = np.array([us[k], vs[k]])
        b = np.array([us[(k + 1) % len(us)], vs[(k + 1) % len(us)]])
        t = np.clip(np.dot([u, v] - a, b - a) / max(np.dot(b - a, b - a), 1e-300), 0.0, 1.0)
        best = min(best, float(np.hypot(*(a + t * (b - a) - [u, v]))))
    return best


@pytest.mark.parametrize("scene_name", ["paper", "dense", "blocked-front"])
def test_matches_reference_zbuffer(scene_name: str) -> None:
    scene = load_scene(scene_name)
    for pose in POSES:
        if not _inside_a_building(scene, pose):
            _assert_same_but_ties(scene, pose, SMALL)


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    e=st.floats(-40, 40),
    n=st.floats(-40, 40),
    u=st.floats(0.5, 60),
    yaw=st.floats(0, 360),
    pitch=st.floats(-90, 10),
)
def test_random_scenes_match_reference(
    seed: int, e: float, n: float, u: float, yaw: float, pitch: float
) -> None:
    scene = generate_scene(seed=seed, buildings=6)
    pose = CameraPose((e, n, u), yaw, pitch)
    # within the near plane of a wall (3 mm from one, seed 4059) the renderer clips what the
    # reference's rays still see: no pose to compare them at
    assume(not _near_a_building(scene, pose, NEAR_M))
    _assert_same_but_ties(scene, pose, SMALL)
    # the per-pixel depth-test path (used when the order has a cycle) agrees exactly
    fast = render(scene, pose, SMALL)
    assert np.array_equal(
        rgb_from_packed(render_packed(scene, pose, SMALL, force_depth_test=True)), fast
    )


def test_frames_are_identical_across_runs_and_machines() -> None:
    scene = load_scene("paper")
    first = render(scene, NADIR_45, K)
    assert np.array_equal(first, render(scene, NADIR_45, K))
    # golden digests: a change here changes every golden recording that renders frames
    assert hashlib.sha256(first.tobytes()).hexdigest() == GOLDEN["paper-nadir45"]
    front = render(scene, FRONT_OF_RED, K)
    assert hashlib.sha256(front.tobytes()).hexdigest() == GOLDEN["paper-front"]
    noisy = render(scene, NADIR_45, K, noise_seed=7)
    assert hashlib.sha256(noisy.tobytes()).hexdigest() == GOLDEN["paper-nadir45-noise7"]


def test_noise_is_seeded_and_small() -> None:
    scene = load_scene("paper")
    clean = render(scene, NADIR_45, K).astype(np.int16)
    a = render(scene, NADIR_45, K, noise_seed=1)
    assert np.array_equal(a, render(scene, NADIR_45, K, noise_seed=1))
    assert not np.array_equal(a, render(scene, NADIR_45, K, noise_seed=2))
    diff = a.astype(np.int16) - clean
    assert abs(float(diff.mean())) < 0.05
    assert 2.5 < float(diff.std()) < 3.5
    assert int(np.abs(diff).max()) <= 12


def test_shading_keeps_hue_and_roofs_brightest() -> None:
    import cv2

    scene = load_scene("paper")
    for b in scene.buildings:
        colours = {shade(b.color_rgb, tuple(n), scene) for n in prepare(scene).normals.tolist()}
        roof = _roof_rgb(scene, b.name)
        assert sum(roof) == max(sum(c) for c in colours)
        hsv = cv2.cvtColor(np.array([list(colours)], dtype=np.uint8), cv2.COLOR_RGB2HSV)[0]
        assert int(hsv[:, 0].max()) - int(hsv[:, 0].min()) <= 3  # OpenCV hue: 2 degrees per step


GOLDEN = {
    "paper-nadir45": "7321dccc4558cbea7bbfc3767620b41c1320d1acf378cd304af4a04ba0fbe9a1",
    "paper-front": "0f51cbedd632db882e3c9b7b50e23b4841ada85c094608ac3846b0227cf817cd",
    "paper-nadir45-noise7": "ebea50871a089a15d23409051790ca681a61c7afbc6c48a761ded63584f699fa",
}
