"""Pixels to ground: hand-computed nadir and oblique cases, and a round trip through project."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.errors import FailureError
from uavtool.nav import NavError, ground_point, ground_polygon, poi_offset

K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
TAN_H = math.tan(math.radians(30.0))  # half the horizontal field of view
TAN_V = 240.0 / K.fy_px  # half the vertical field, from the pixel count
RIGHT_EDGE = (639.5, K.cy_px)  # outer edge of the last column, centre row
TOP_EDGE = (K.cx_px, -0.5)


def nadir(alt_m: float, heading_deg: float = 0.0) -> CameraPose:
    return CameraPose((0.0, 0.0, alt_m), heading_deg, -90.0)


@pytest.mark.parametrize("alt_m", [5.0, 20.0, 45.0, 120.0])
def test_nadir_centre_edges_and_corner(alt_m: float) -> None:
    assert ground_point(K.cx_px, K.cy_px, nadir(alt_m), K) == pytest.approx((0.0, 0.0), abs=1e-12)
    east, north = ground_point(*RIGHT_EDGE, nadir(alt_m), K)
    assert east == pytest.approx(alt_m * TAN_H, rel=1e-12)
    assert north == pytest.approx(0.0, abs=1e-12)
    east, north = ground_point(*TOP_EDGE, nadir(alt_m), K)
    assert (east, north) == pytest.approx((0.0, alt_m * TAN_V), abs=1e-12)
    # bottom-left pixel centre: half a pixel inside the corner
    east, north = ground_point(0.0, 479.0, nadir(alt_m), K)
    assert east == pytest.approx(-alt_m * (319.5 / K.fx_px), rel=1e-12)
    assert north == pytest.approx(-alt_m * (239.5 / K.fy_px), rel=1e-12)


@pytest.mark.parametrize(
    ("heading_deg", "north_east"),
    [
        (0.0, (0.0, 1.0)),  # image right = east
        (90.0, (-1.0, 0.0)),  # heading east: image right = south
        (180.0, (0.0, -1.0)),
        (270.0, (1.0, 0.0)),
        (30.0, (-0.5, math.cos(math.radians(30.0)))),
    ],
)
def test_poi_offset_turns_with_heading(heading_deg: float, north_east: tuple[float, float]) -> None:
    alt_m = 45.0
    north, east = poi_offset(*RIGHT_EDGE, alt_m=alt_m, heading_deg=heading_deg, intrinsics=K)
    x = alt_m * TAN_H
    assert north == pytest.approx(north_east[0] * x, abs=1e-9)
    assert east == pytest.approx(north_east[1] * x, abs=1e-9)


def test_poi_offset_top_of_image_is_ahead() -> None:
    north, east = poi_offset(*TOP_EDGE, alt_m=10.0, heading_deg=90.0, intrinsics=K)
    assert (north, east) == pytest.approx((0.0, 10.0 * TAN_V), abs=1e-12)


def test_wider_field_of_view_sees_farther() -> None:
    wide = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=90.0)
    north, east = poi_offset(639.5, wide.cy_px, alt_m=20.0, heading_deg=0.0, intrinsics=wide)
    assert (north, east) == pytest.approx((0.0, 20.0), abs=1e-12)  # tan 45° = 1


def test_gimbal_pitched_minus_60() -> None:
    pose = CameraPose((3.0, -2.0, 30.0), 0.0, -60.0)
    # optical axis 60° below the horizon: hits the ground alt / tan 60° ahead (north)
    east, north = ground_point(K.cx_px, K.cy_px, pose, K)
    assert (east, north) == pytest.approx((3.0, -2.0 + 30.0 / math.tan(math.radians(60.0))))
    # a pixel 10° above the axis: 50° below the horizon
    v = K.cy_px - K.fy_px * math.tan(math.radians(10.0))
    east, north = ground_point(K.cx_px, v, pose, K)
    assert (east, north) == pytest.approx((3.0, -2.0 + 30.0 / math.tan(math.radians(50.0))))
    # the same, facing east, as poi_offset from a 30 m altitude
    north, east = poi_offset(
        K.cx_px, v, alt_m=30.0, heading_deg=90.0, intrinsics=K, gimbal_pitch_deg=-60.0
    )
    assert (north, east) == pytest.approx((0.0, 30.0 / math.tan(math.radians(50.0))), abs=1e-9)


def test_plane_above_ground() -> None:
    got = ground_point(*RIGHT_EDGE, nadir(20.0), K, plane_z_m=5.0)
    assert got == pytest.approx((15.0 * TAN_H, 0.0), abs=1e-12)


def test_rays_that_miss_the_ground_raise() -> None:
    pitched = CameraPose((0.0, 0.0, 30.0), 0.0, -10.0)
    above = K.cy_px - K.fy_px * math.tan(math.radians(20.0))  # 10° above the horizon
    with pytest.raises(NavError, match="above the horizon"):
        ground_point(K.cx_px, above, pitched, K)
    with pytest.raises(NavError, match="above the horizon"):
        ground_point(K.cx_px, K.cy_px, CameraPose((0.0, 0.0, 30.0), 0.0, 0.0), K)
    with pytest.raises(NavError, match="not above the plane"):
        ground_point(K.cx_px, K.cy_px, nadir(3.0), K, plane_z_m=3.0)
    with pytest.raises(NavError, match="altitude"):
        poi_offset(1.0, 1.0, alt_m=0.0, heading_deg=0.0, intrinsics=K)
    with pytest.raises(NavError, match="not finite"):
        ground_point(math.nan, 1.0, nadir(3.0), K)
    assert issubclass(NavError, FailureError)


def test_ground_polygon_maps_each_vertex() -> None:
    ring = np.array(
        [
            [K.cx_px - 100, K.cy_px - 50],
            [K.cx_px + 100, K.cy_px - 50],
            [K.cx_px + 100, K.cy_px + 50],
        ]
    )
    got = ground_polygon(ring, nadir(10.0, 180.0), K)
    s = 10.0 / K.fx_px  # metres per pixel at the image centre
    # heading 180: image right = west, image up = south
    want = [(100 * s, -50 * s), (-100 * s, -50 * s), (-100 * s, 50 * s)]
    assert len(got) == 3
    for g, w in zip(got, want, strict=True):
        assert g == pytest.approx(w, abs=1e-12)
    with pytest.raises(NavError, match="shape"):
        ground_polygon(np.zeros((3, 3)), nadir(10.0), K)


@settings(max_examples=300, deadline=None)
@given(
    u=st.floats(-0.5, 639.5),
    v=st.floats(-0.5, 479.5),
    alt_m=st.floats(1.0, 150.0),
    heading_deg=st.floats(0.0, 360.0, exclude_max=True),
    pitch_deg=st.floats(-90.0, -30.0),
    x_m=st.floats(-500.0, 500.0),
    plane_z_m=st.floats(-5.0, 0.5),
)
def test_round_trip_through_project(
    u: float,
    v: float,
    alt_m: float,
    heading_deg: float,
    pitch_deg: float,
    x_m: float,
    plane_z_m: float,
) -> None:
    pose = CameraPose((x_m, -x_m / 3.0, alt_m), heading_deg, pitch_deg)
    east, north = ground_point(u, v, pose, K, plane_z_m=plane_z_m)
    back = project(np.array([[east, north, plane_z_m]]), pose, K)[0]
    assert back[2] > 0.0
    assert abs(back[0] - u) < 1e-9
    assert abs(back[1] - v) < 1e-9
