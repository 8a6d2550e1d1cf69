"""Front/right/top viewpoints: hand-checked positions, each fallback, and the built-in scenes."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.errors import InputError
from uavtool.nav import (
    NavParamError,
    Rect,
    Viewpoint,
    ViewpointFailure,
    ViewpointParams,
    min_area_rect,
    plan_diagonal,
    plan_viewpoints,
    top_viewpoint,
)
from uavtool.nav.geometry import point_polygon_distance, triangle_hits_polygon
from uavtool.nav.viewpoints import base_distance_m, farther, for_building
from uavtool.world import building_footprint, load_scene

K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
P = ViewpointParams()
# 10 m east–west by 8 m, centred on home: long-a is the south side, short-a the east side.
BOX = Rect((0.0, 0.0), 90.0, 10.0, 8.0)
# Vertical fit decides: (1 + 0.25) · max(12 − 6, 6) / tan(vfov/2), tan(vfov/2) = 0.75 tan 30°.
D0 = 10.0 * math.sqrt(3.0)


def square(cx: float, cy: float, half: float) -> list[tuple[float, float]]:
    return [
        (cx - half, cy - half),
        (cx + half, cy - half),
        (cx + half, cy + half),
        (cx - half, cy + half),
    ]


def plan(obstacles, params: ViewpointParams = P):
    front, right = plan_viewpoints(BOX, obstacles, K, params)
    return front, right


def assert_view(v, *, pos, heading, side, distance, fallback="") -> None:
    assert isinstance(v, Viewpoint), v
    assert v.pos_enu_m == pytest.approx(pos, abs=1e-9)
    assert v.heading_deg == pytest.approx(heading, abs=1e-9)
    assert (v.side, v.fallback) == (side, fallback)
    assert v.distance_m == pytest.approx(distance)


def test_free_field() -> None:
    front, right = plan([])
    assert_view(front, pos=(0.0, -4.0 - D0, 6.0), heading=0.0, side="long-a", distance=D0)
    # right = front − 90: the camera east of the building, looking west
    assert_view(right, pos=(5.0 + D0, 0.0, 6.0), heading=270.0, side="short-a", distance=D0)


def test_long_building_is_fitted_horizontally() -> None:
    long_box = Rect((0.0, 0.0), 0.0, 40.0, 6.0)  # 40 m north–south
    front, _ = plan_viewpoints(long_box, [], K, P)
    d = 1.25 * 20.0 / math.tan(math.radians(30.0))
    # long axis north: long-a faces east, the camera looks west
    assert_view(front, pos=(3.0 + d, 0.0, 6.0), heading=270.0, side="long-a", distance=d)


@pytest.mark.parametrize(("axis_deg", "front_heading"), [(90.0, 0.0), (30.0, 300.0), (150.0, 60.0)])
def test_views_see_the_whole_side(axis_deg: float, front_heading: float) -> None:
    rect = Rect((5.0, -3.0), axis_deg, 14.0, 6.0)
    front, right = plan_viewpoints(rect, [], K, P)
    assert isinstance(front, Viewpoint)
    assert isinstance(right, Viewpoint)
    assert front.heading_deg == pytest.approx(front_heading)
    assert right.heading_deg == pytest.approx((front_heading - 90.0) % 360.0)
    # every corner of the rectangle, at the ground and at the assumed height, is in the image
    corners = [(x, y, z) for x, y in rect.corners() for z in (0.0, P.assumed_height_m)]
    for v in (front, right):
        px = project(np.array(corners), CameraPose(v.pos_enu_m, v.heading_deg, 0.0), K)
        assert np.all(px[:, 2] > 0)
        assert np.all((px[:, 0] >= -0.5) & (px[:, 0] <= 639.5))
        assert np.all((px[:, 1] >= -0.5) & (px[:, 1] <= 479.5))


def test_obstacle_at_the_front_camera_gives_the_opposite_side() -> None:
    front, right = plan([square(0.0, -4.0 - D0, 3.0)])
    assert_view(
        front,
        pos=(0.0, 4.0 + D0, 6.0),
        heading=180.0,
        side="long-b",
        distance=D0,
        fallback="opposite side",
    )
    # right is relative to the actual front heading: 180 − 90 = 90, camera west of the building
    assert_view(right, pos=(-5.0 - D0, 0.0, 6.0), heading=90.0, side="short-b", distance=D0)


def test_line_of_sight_blocked_but_camera_clear() -> None:
    wall = [(-1.0, -12.0), (1.0, -12.0), (1.0, -11.0), (-1.0, -11.0)]  # 9 m from the camera
    front, _ = plan([wall])
    assert_view(
        front,
        pos=(0.0, 4.0 + D0, 6.0),
        heading=180.0,
        side="long-b",
        distance=D0,
        fallback="opposite side",
    )
    walls = [wall, [(x, -y) for x, y in wall]]
    square_on = ViewpointParams(max_distance_m=20.0, oblique_deg=())  # base distance only
    front, right = plan(walls, square_on)
    assert isinstance(front, ViewpointFailure)
    assert front.reason == (
        "front: long-a at 17.3 m: no line of sight (obstacle 0); "
        "long-b at 17.3 m: no line of sight (obstacle 1); "
        "long-a looking down: no line of sight; long-b looking down: no line of sight "
        "(tried up to 20 m)"
    )
    assert_view(right, pos=(5.0 + D0, 0.0, 6.0), heading=270.0, side="short-a", distance=D0)


def test_blocked_square_on_the_camera_turns_around_the_building() -> None:
    """Both long sides hidden by walls straight in front of them: the camera turns 25°
    around the building, where it sees all four corners past the walls."""
    wall = [(-1.0, -12.0), (1.0, -12.0), (1.0, -11.0), (-1.0, -11.0)]
    walls = [wall, [(x, -y) for x, y in wall]]
    front, _ = plan(walls, ViewpointParams(max_distance_m=40.0))
    assert isinstance(front, Viewpoint)
    assert front.fallback.startswith("turned +25° from the long-")
    cam = front.pos_enu_m[:2]
    corners = [(-5.0, -4.0), (5.0, -4.0), (5.0, 4.0), (-5.0, 4.0)]
    for wall_ring in walls:
        for i, a in enumerate(corners):
            for b in corners[i + 1 :]:
                assert not triangle_hits_polygon((cam, a, b), wall_ring)
    assert min(point_polygon_distance(cam, w) for w in walls) >= P.safety_margin_m


def test_a_right_camera_turned_round_looks_far_enough_from_the_front_one() -> None:
    """Every side hidden square on: the front camera turns +25° (heading 335°); with the
    right's +25° places taken, its first fit is turned -25°, 40° from the front's direction.
    Asked for 60° apart (the model's least separation), it turns +45° instead (110°)."""
    wall = [(-1.0, -12.0), (1.0, -12.0), (1.0, -11.0), (-1.0, -11.0)]
    post = [(12.0, -1.0), (13.0, -1.0), (13.0, 1.0), (12.0, 1.0)]
    walls = [wall, [(x, -y) for x, y in wall], post, [(-x, y) for x, y in post]]
    taken = [square(16.3, 7.6, 2.0), square(-16.3, -7.6, 2.0)]
    params = ViewpointParams(max_distance_m=40.0)
    for apart, heading in ((0.0, 295.0), (60.0, 225.0)):
        front, right = plan_viewpoints(BOX, walls + taken, K, params, None, apart)
        assert isinstance(front, Viewpoint) and front.heading_deg == pytest.approx(335.0)
        assert isinstance(right, Viewpoint), right
        assert right.heading_deg == pytest.approx(heading)


def test_obstacles_by_both_long_side_cameras_give_a_larger_distance() -> None:
    # 3 m east of each base camera position, outside the line of sight; clear at 1.25 × D0
    posts = [
        [(3.0, y - 1.0), (5.0, y - 1.0), (5.0, y + 1.0), (3.0, y + 1.0)]
        for y in (-4.0 - D0, 4.0 + D0)
    ]
    front, right = plan(posts)
    assert_view(
        front,
        pos=(0.0, -4.0 - 1.25 * D0, 6.0),
        heading=0.0,
        side="long-a",
        distance=1.25 * D0,
        fallback="distance 1.25x",
    )
    assert_view(right, pos=(5.0 + D0, 0.0, 6.0), heading=270.0, side="short-a", distance=D0)


def test_fully_boxed_in() -> None:
    walls = [
        [(-20, -10), (20, -10), (20, -9), (-20, -9)],
        [(-20, 9), (20, 9), (20, 10), (-20, 10)],
        [(-10, -8), (-9, -8), (-9, 8), (-10, 8)],
        [(9, -8), (10, -8), (10, 8), (9, 8)],
    ]
    front, right = plan(walls)
    assert isinstance(front, ViewpointFailure)
    assert isinstance(right, ViewpointFailure)
    assert front.reason.startswith(
        "front: long-a at 17.3 m: no line of sight (obstacle 0); long-b at 17.3 m"
    )
    assert "long-b at 52.9 m: no line of sight (obstacle 1)" in front.reason  # 17.3 · 1.25⁵
    assert front.reason.endswith("(tried up to 60 m)")
    assert "obstacle 3" in right.reason and "obstacle 2" in right.reason


def test_camera_inside_an_obstacle_is_named() -> None:
    front, _ = plan(
        [[(-30, -40), (30, -40), (30, 40), (-30, 40)]], ViewpointParams(max_distance_m=18.0)
    )
    assert isinstance(front, ViewpointFailure)
    assert (
        "long-a at 17.3 m: within 4 m of obstacle 0 (0.0 m) and no line of sight (obstacle 0)"
        in front.reason
    )


def test_base_distance_beyond_the_limit() -> None:
    front, _ = plan([], ViewpointParams(max_distance_m=10.0, max_pitch_down_deg=0.0))
    assert front == ViewpointFailure(
        "front",
        "front: the base distance 17.3 m exceeds nav.max_distance_m 10 m (tried up to 10 m)",
    )
    front, _ = plan([], ViewpointParams(max_distance_m=10.0))
    assert isinstance(front, ViewpointFailure)
    assert front.reason == (
        "front: the base distance 17.3 m exceeds nav.max_distance_m 10 m; "
        "long-a looking down: too close to look down at steeply enough; "
        "long-b looking down: too close to look down at steeply enough (tried up to 10 m)"
    )


@pytest.mark.parametrize("tall_m", [45.0, 55.0, 70.0])
def test_a_tower_too_tall_for_a_level_camera_is_photographed_looking_down(tall_m: float) -> None:
    """A level camera needs 65-101 m to hold a 45-70 m tower, more than ``max_distance_m``
    (60 m): the camera rises and looks down, no steeper than ``max_pitch_down_deg``, and
    its view holds the building's every corner from the ground to its top."""
    params = ViewpointParams(assumed_height_m=tall_m, camera_alt_m=tall_m / 2.0)
    assert base_distance_m(BOX.length_m, K, params) > params.max_distance_m
    front, right = plan([], params)
    for vp in (front, right):
        assert isinstance(vp, Viewpoint), vp
        assert -params.max_pitch_down_deg <= vp.pitch_deg < 0.0
        assert "looking down" in vp.fallback and vp.distance_m <= params.max_distance_m
        assert vp.pos_enu_m[2] > params.camera_alt_m
        pose = CameraPose(vp.pos_enu_m, vp.heading_deg, vp.pitch_deg)
        corners = BOX.corners()
        points = [(x, y, z) for x, y in corners for z in (0.0, tall_m)]
        uvz = project(np.array(points), pose, K)
        assert (uvz[:, 2] > 0.0).all()
        assert (uvz[:, 0] >= 0.0).all() and (uvz[:, 0] <= K.width_px - 1).all()
        assert (uvz[:, 1] >= 0.0).all() and (uvz[:, 1] <= K.height_px - 1).all()


def test_top_viewpoint() -> None:
    v = top_viewpoint(BOX, 180.0, alt_m=20.0)
    assert v == Viewpoint("top", (0.0, 0.0, 20.0), 180.0, "top", 20.0, "", -90.0)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("margin", -0.1),
        ("camera_alt_m", 0.0),
        ("assumed_height_m", -1.0),
        ("safety_margin_m", -1.0),
        ("max_distance_m", math.inf),
        ("distance_step", 1.0),
        ("margin", math.nan),
    ],
)
def test_params_are_validated(field: str, value: float) -> None:
    with pytest.raises(NavParamError, match=f"nav.{field} must"):
        ViewpointParams(**{field: value})
    assert issubclass(NavParamError, InputError)


def scene_plan(name: str):
    scene = load_scene(name)
    fp = building_footprint(scene.building(scene.target))
    rect = min_area_rect(list(fp.exterior.coords))
    others = [
        list(building_footprint(b).exterior.coords)
        for b in scene.buildings
        if b.name != scene.target
    ]
    return plan_viewpoints(rect, others, K, P)


def test_paper_scene_needs_no_fallback() -> None:
    front, right = scene_plan("paper")
    assert_view(front, pos=(10.0, -12.0 - D0, 6.0), heading=0.0, side="long-a", distance=D0)
    assert_view(right, pos=(15.0 + D0, -8.0, 6.0), heading=270.0, side="short-a", distance=D0)


def test_blocked_front_scene_falls_back_to_the_north() -> None:
    front, right = scene_plan("blocked-front")
    assert_view(
        front,
        pos=(10.0, -4.0 + D0, 6.0),
        heading=180.0,
        side="long-b",
        distance=D0,
        fallback="opposite side",
    )
    # right of a north camera is west, where the blue building stands: east side instead
    assert_view(
        right,
        pos=(15.0 + D0, -8.0, 6.0),
        heading=270.0,
        side="short-a",
        distance=D0,
        fallback="opposite side",
    )


def test_diagonal_looks_across_the_corner_between_front_and_right() -> None:
    """Front from the south, right from the east: the diagonal camera stands south-east of
    the centre and looks north-west, at the distance that fits the box's extent across
    that direction (its diagonal, 10·cos45° + 8·cos45°)."""
    front, right = plan([])
    assert isinstance(front, Viewpoint) and isinstance(right, Viewpoint)
    diag = plan_diagonal(BOX, front.pos_enu_m, right.pos_enu_m, [], K, P)
    assert isinstance(diag, Viewpoint), diag
    assert diag.name == "diagonal" and diag.heading_deg == pytest.approx(315.0)
    across = (10.0 + 8.0) / math.sqrt(2.0)
    d = base_distance_m(across, K, P)
    depth = 9.0 / math.sqrt(2.0)  # the corner (5, −4) along the south-east unit vector
    r = (depth + d) / math.sqrt(2.0)
    assert diag.pos_enu_m == pytest.approx((r, -r, P.camera_alt_m))
    assert diag.fallback == "between the front and right cameras"


def test_diagonal_blocked_goes_behind_both_cameras() -> None:
    front, right = plan([])
    assert isinstance(front, Viewpoint) and isinstance(right, Viewpoint)
    wall = square(9.0, -9.0, 1.0)  # between the box's south-east corner and that camera
    diag = plan_diagonal(BOX, front.pos_enu_m, right.pos_enu_m, [wall], K, P)
    assert isinstance(diag, Viewpoint), diag
    assert diag.fallback == "behind the front and right cameras"
    assert diag.heading_deg == pytest.approx(135.0)  # from the north-west, looking south-east
    boxed = [square(x, y, 3.0) for x in (-17.0, 17.0) for y in (-17.0, 17.0)]  # every diagonal
    failure = plan_diagonal(
        BOX, front.pos_enu_m, right.pos_enu_m, boxed, K, ViewpointParams(max_distance_m=30.0)
    )
    assert isinstance(failure, ViewpointFailure)
    assert failure.reason.startswith("diagonal: between the front and right cameras: ")


def _clear(
    eye: tuple[float, float, float], point: tuple[float, float, float], walls, heights
) -> bool:
    """Whether the straight line from ``eye`` to ``point`` passes over every wall (sampled
    every 5 cm: an independent check of the planner's own crossing test)."""
    n = int(math.dist(eye, point) / 0.05) + 1
    for i in range(n + 1):
        t = i / n
        x, y, z = (e + (p - e) * t for e, p in zip(eye, point, strict=True))
        for wall, h in zip(walls, heights, strict=True):
            xs, ys = [q[0] for q in wall], [q[1] for q in wall]
            if min(xs) < x < max(xs) and min(ys) < y < max(ys) and z < h:
                return False
    return True


def _ring(*, gap_m: float, thick_m: float) -> list[list[tuple[float, float]]]:
    """Four walls round BOX, ``gap_m`` from its sides and ``thick_m`` thick."""
    x, y, t = 5.0 + gap_m, 4.0 + gap_m, thick_m
    return [
        [(-x - t, -y - t), (x + t, -y - t), (x + t, -y), (-x - t, -y)],
        [(-x - t, y), (x + t, y), (x + t, y + t), (-x - t, y + t)],
        [(-x - t, -y), (-x, -y), (-x, y), (-x - t, y)],
        [(x, -y), (x + t, -y), (x + t, y), (x, y)],
    ]


def test_walls_round_a_building_are_seen_over_from_as_high_as_needed() -> None:
    """The 12 m box inside a ring of 9 m walls 8 m out from its sides, 2 m thick: no level
    camera sees it, and the lowest camera that holds the box looking down sees only the top
    of its walls over them. The camera rises until it sees every corner of its side from
    the top down to half the box's height (the silhouette the model is carved from), never
    steeper than ``max_pitch_down_deg``, and keeps the safety margin from the walls."""
    walls = _ring(gap_m=8.0, thick_m=2.0)
    heights = [9.0] * 4
    front, right = plan_viewpoints(BOX, walls, K, P, heights)
    for vp in (front, right):
        assert isinstance(vp, Viewpoint), vp
        assert -P.max_pitch_down_deg <= vp.pitch_deg < 0.0
        x, y, z = vp.pos_enu_m
        assert all(point_polygon_distance((x, y), w) >= P.safety_margin_m for w in walls)
        near = [c for c in BOX.corners() if math.dist(c, (x, y)) < math.dist(BOX.center_en, (x, y))]
        for cx, cy in near:
            for at in (P.assumed_height_m, P.assumed_height_m / 2.0):
                assert _clear((x, y, z), (cx, cy, at), walls, heights)


def test_walls_hiding_half_of_a_building_leave_its_roof_line_to_be_seen() -> None:
    """The 12 m box inside a ring of 11.5 m walls a metre from its sides: within the pitch
    limit no camera sees half its walls' height over them (worlds 50088, 50102: a neighbour
    as tall as the target beside it, and no side photo was planned). The model carves
    nothing below what a photo sees, so asked to (``roof_line``), a last round plans a
    camera that sees every roof corner over the walls; its fallback says so."""
    walls = _ring(gap_m=1.0, thick_m=1.0)
    heights = [11.5] * 4
    front, right = plan_viewpoints(BOX, walls, K, P, heights)
    assert isinstance(front, ViewpointFailure) and isinstance(right, ViewpointFailure)
    front, right = plan_viewpoints(BOX, walls, K, P, heights, roof_line=True)
    tall = P.assumed_height_m
    for vp in (front, right):
        assert isinstance(vp, Viewpoint), vp
        assert "over its neighbours to its roof line" in vp.fallback
        assert -P.max_pitch_down_deg <= vp.pitch_deg < 0.0
        x, y, z = vp.pos_enu_m
        assert all(point_polygon_distance((x, y), w) >= P.safety_margin_m for w in walls)
        near = [c for c in BOX.corners() if math.dist(c, (x, y)) < math.dist(BOX.center_en, (x, y))]
        assert all(_clear((x, y, z), (cx, cy, tall), walls, heights) for cx, cy in near)
        assert not all(_clear((x, y, z), (cx, cy, tall / 2.0), walls, heights) for cx, cy in near)
    # walls taller than the building: not even its roof line shows over them
    front, right = plan_viewpoints(BOX, walls, K, P, [tall + 20.0] * 4, roof_line=True)
    assert isinstance(front, ViewpointFailure) and isinstance(right, ViewpointFailure)
    assert "over its neighbours to its roof line: no line of sight" in front.reason


def test_a_tower_too_tall_for_the_distance_limit_is_planned_from_farther() -> None:
    """A 57 m tower: a level camera halfway up must stand 82.7 m off to hold it with the
    margin, beyond the 60 m limit, so no level view is planned. ``farther`` stretches the
    limit to that distance, one step beyond, and the level view is found; a limit stretched
    further than two steps (a user's 5 m) stays short of it."""
    tower = Rect((0.0, 0.0), 90.0, 12.0, 12.0)
    params = for_building(ViewpointParams(), 57.3, least_alt_m=6.0)
    assert params.camera_alt_m == pytest.approx(28.65)
    held_m = 1.25 * 28.65 / math.tan(math.radians(K.vfov_deg) / 2.0)
    assert held_m == pytest.approx(82.7, abs=0.1)
    front, right = plan_viewpoints(tower, [], K, replace(params, max_pitch_down_deg=0.0))
    assert isinstance(front, ViewpointFailure) and isinstance(right, ViewpointFailure)
    far = farther(params, K)
    assert far is not None and far.max_distance_m == pytest.approx(min(held_m, 75.0) * 1.25)
    front, right = plan_viewpoints(tower, [], K, replace(far, max_pitch_down_deg=0.0))
    assert isinstance(front, Viewpoint) and front.pitch_deg == 0.0
    assert front.distance_m == pytest.approx(held_m, abs=0.5)
    assert isinstance(right, Viewpoint)
    assert farther(ViewpointParams(), K) is None  # 12 m: the limit holds it already
    near = farther(replace(params, max_distance_m=5.0), K)
    assert near is not None and near.max_distance_m == pytest.approx(5.0 * 1.25**2)
