"""Roof heights from two nadir photos, against hand-computed geometry and rendered scenes."""

from __future__ import annotations

import math

import pytest

from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission import Params
from uavtool.mission.analysis import nadir_shapes
from uavtool.nav.heights import fit_altitude_m, roof_from_photos, roof_height_m
from uavtool.world import load_scene, render

K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)


def test_hand_computed_roof() -> None:
    """A 10 m square roof 6 m high, from 45 m and 60 m: f·W/(a−h) pixels across."""
    f_px = K.fx_px
    side45, side60 = f_px * 10.0 / 39.0, f_px * 10.0 / 54.0
    h = roof_height_m(area1_px=side45**2, alt1_m=45.0, area2_px=side60**2, alt2_m=60.0)
    assert h == pytest.approx(6.0, abs=1e-9)
    # The order of the photos does not matter.
    assert roof_height_m(
        area1_px=side60**2, alt1_m=60.0, area2_px=side45**2, alt2_m=45.0
    ) == pytest.approx(6.0, abs=1e-9)


def test_ground_level_and_ill_conditioned_pairs() -> None:
    f_px = K.fx_px
    flat45, flat60 = (f_px * 8.0 / 45.0) ** 2, (f_px * 8.0 / 60.0) ** 2
    assert roof_height_m(
        area1_px=flat45, alt1_m=45.0, area2_px=flat60, alt2_m=60.0
    ) == pytest.approx(0.0, abs=1e-9)
    # Same size from both: no height can be told (a camera that did not climb).
    assert roof_height_m(area1_px=900.0, alt1_m=45.0, area2_px=900.0, alt2_m=45.0) is None
    assert roof_height_m(area1_px=0.0, alt1_m=45.0, area2_px=900.0, alt2_m=60.0) is None
    # A roof that would be above the cameras: nonsense, not a height.
    assert roof_height_m(area1_px=400.0, alt1_m=45.0, area2_px=900.0, alt2_m=60.0) is None
    # Two sizes from one altitude (a look taken as high as the overview, seeing the roof
    # nearer the centre): they tell nothing of the height.
    assert roof_height_m(area1_px=900.0, alt1_m=97.1, area2_px=1000.0, alt2_m=97.1) is None


def test_two_photos_from_one_altitude_give_the_height_by_triangulation_alone() -> None:
    """Two photos from one altitude tell the height by triangulation alone. (Hard scene 240
    with home turned, `--random-home`, looked at a roof from as high as the overview; sizes
    that differed by rounding gave a size estimate of no variance, and the weighting divided
    by zero: the assertion on `roof_height_m` above.)"""
    roof_m, alt_m, side_m = 12.0, 97.1, 10.0
    poses = [CameraPose((0.0, 0.0, alt_m), 0.0, -90.0), CameraPose((20.0, 0.0, alt_m), 0.0, -90.0)]
    seen = []
    for pose in poses:  # a roof at (20, 0): 20 m east of the first camera, below the second
        u = K.cx_px + K.fx_px * (20.0 - pose.pos_enu_m[0]) / (alt_m - roof_m)
        side_px = K.fx_px * side_m / (alt_m - roof_m) * (1.0 if u == K.cx_px else 0.9)
        seen.append(((u, K.cy_px), side_px**2))
    h = roof_from_photos(
        centroid1_px=seen[0][0],
        area1_px=seen[0][1],
        pose1=poses[0],
        centroid2_px=seen[1][0],
        area2_px=seen[1][1],
        pose2=poses[1],
        intrinsics=K,
    )
    assert h == pytest.approx(roof_m, abs=0.01)


@pytest.mark.parametrize(("name", "tolerance_m"), [("red", 1.0), ("yellow", 2.5), ("blue", 2.5)])
def test_rendered_roofs_of_paper_by_size_alone(name: str, tolerance_m: float) -> None:
    """From rendered photos straight above each of paper's buildings, by size alone: within
    a few metres (a 1 % error in a roof's size moves the estimate from 45 m and 60 m by about
    1.7 m — which is why the mission also triangulates)."""
    scene = load_scene("paper")
    building = scene.building(name)
    xs = [x for b in building.blocks for x, _ in b.footprint_enu_m]
    ys = [y for b in building.blocks for _, y in b.footprint_enu_m]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    areas = []
    for alt in (45.0, 60.0):
        image = render(scene, CameraPose((cx, cy, alt), 0.0, -90.0), K)
        shapes = nadir_shapes(Params(), image)
        centre = min(shapes, key=lambda s: math.dist(s.centroid_px, (K.cx_px, K.cy_px)))
        areas.append(centre.area_px)
    h = roof_height_m(area1_px=areas[0], alt1_m=45.0, area2_px=areas[1], alt2_m=60.0)
    tops = [b.top_m for b in building.blocks]
    assert h is not None
    assert min(tops) - tolerance_m <= h <= max(tops) + tolerance_m


def test_fit_altitude_puts_the_roof_in_the_frame() -> None:
    """A 20 m footprint spanning half the photo's height (480 px, 45° vertical FOV)."""
    alt = fit_altitude_m(roof_m=10.0, extent_m=20.0, intrinsics=K, fill=0.5)
    span_px = K.fy_px * 20.0 / (alt - 10.0)
    assert span_px == pytest.approx(0.5 * 480.0)


@pytest.mark.parametrize("name", ["red", "yellow", "blue", "purple"])
@pytest.mark.parametrize("offset", [(0.0, 0.0), (3.0, -2.0)])
def test_rendered_roofs_from_the_overview_pair(name: str, offset: tuple[float, float]) -> None:
    """Paper from 45 m and 60 m above home (or a little beside it for the second photo), as
    the mission's overviews: every roof within 1 m (red's two roofs: between them) — well
    inside the margins the mission keeps above roofs."""
    scene = load_scene("paper")
    building = scene.building(name)
    params = Params()
    poses = [CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), CameraPose((*offset, 60.0), 0.0, -90.0)]
    seen = []
    for pose in poses:
        shapes = nadir_shapes(params, render(scene, pose, K))
        seen.append(next(s for s in shapes if s.colour_rgb == _roof_rgb(shapes, building)))
    h = roof_from_photos(
        centroid1_px=seen[0].centroid_px,
        area1_px=seen[0].area_px,
        pose1=poses[0],
        centroid2_px=seen[1].centroid_px,
        area2_px=seen[1].area_px,
        pose2=poses[1],
        intrinsics=K,
    )
    tops = [b.top_m for b in building.blocks]
    assert h is not None
    assert min(tops) - 1.0 <= h <= max(tops) + 1.0


def _roof_rgb(shapes, building):  # type: ignore[no-untyped-def]
    """The colour of the shape nearest the building's own colour."""
    return min(
        (s.colour_rgb for s in shapes),
        key=lambda c: sum(abs(a - b) for a, b in zip(c, building.color_rgb, strict=True)),
    )
