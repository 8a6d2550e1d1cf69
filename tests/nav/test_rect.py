"""The minimum-area rectangle: hand-made shapes and hypothesis invariants."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uavtool.nav import NavError, Rect, min_area_rect


def rotated(
    points: list[tuple[float, float]], heading_deg: float, shift=(0.0, 0.0)
) -> list[tuple[float, float]]:
    """Turn points clockwise by ``heading_deg`` (a north-pointing vector gets that heading)."""
    t = math.radians(heading_deg)
    s, c = math.sin(t), math.cos(t)
    return [(x * c + y * s + shift[0], -x * s + y * c + shift[1]) for x, y in points]


def assert_rect(r: Rect, center, axis_deg, length, width) -> None:
    assert r.center_en == pytest.approx(center, abs=1e-9)
    assert r.long_axis_deg == pytest.approx(axis_deg, abs=1e-9)
    assert (r.length_m, r.width_m) == pytest.approx((length, width), abs=1e-9)


def test_axis_aligned_with_inner_points() -> None:
    pts = [(0, 0), (10, 0), (10, 4), (0, 4), (3, 2), (9, 1), (5, 4)]
    assert_rect(min_area_rect(pts), (5.0, 2.0), 90.0, 10.0, 4.0)
    tall = [(y, x) for x, y in pts]  # long along north
    assert_rect(min_area_rect(np.array(tall, dtype=float)), (2.0, 5.0), 0.0, 10.0, 4.0)


@pytest.mark.parametrize("heading_deg", [30.0, 75.0, 120.0, 179.0])
def test_rotated_rectangle(heading_deg: float) -> None:
    # 12 m long (along north before turning), 5 m wide, centred at (7, -3)
    box = [(-2.5, -6.0), (2.5, -6.0), (2.5, 6.0), (-2.5, 6.0), (0.0, 1.0)]
    r = min_area_rect(rotated(box, heading_deg, (7.0, -3.0)))
    assert_rect(r, (7.0, -3.0), heading_deg, 12.0, 5.0)


def test_l_shape_is_the_bounding_box() -> None:
    # the paper scene's red building: south wing and east leg
    ell = [(5, -12), (15, -12), (15, -4), (11.5, -4), (11.5, -8.5), (5, -8.5)]
    r = min_area_rect(ell)
    assert_rect(r, (10.0, -8.0), 90.0, 10.0, 8.0)
    corners = [v for corner in sorted(r.corners()) for v in corner]
    assert corners == pytest.approx([5, -12, 5, -4, 15, -12, 15, -4])


def test_obtuse_triangle_lies_on_its_longest_side() -> None:
    assert_rect(min_area_rect([(0, 0), (10, 0), (2, 2)]), (5.0, 1.0), 90.0, 10.0, 2.0)


def test_ties_do_not_depend_on_input_order() -> None:
    # a right triangle: the legs and the hypotenuse give the same area (12 m²)
    tri = [(0.0, 0.0), (4.0, 0.0), (0.0, 3.0), (1.0, 1.0)]
    results = {min_area_rect(list(p)) for p in itertools.permutations(tri)}
    assert len(results) == 1
    assert results.pop().area_m2 == pytest.approx(12.0)
    square = [(0, 0), (2, 0), (2, 2), (0, 2)]
    assert_rect(min_area_rect(square), (1.0, 1.0), 0.0, 2.0, 2.0)


def test_corners_are_counter_clockwise_and_span_the_sides() -> None:
    r = Rect((1.0, 2.0), 30.0, 10.0, 4.0)
    c = r.corners()
    area2 = sum(c[i][0] * c[(i + 1) % 4][1] - c[(i + 1) % 4][0] * c[i][1] for i in range(4))
    assert area2 / 2.0 == pytest.approx(40.0)
    assert math.dist(c[0], c[1]) == pytest.approx(4.0)
    assert math.dist(c[1], c[2]) == pytest.approx(10.0)
    # c[1] → c[2] runs along the long axis, heading 30°
    assert math.degrees(math.atan2(c[2][0] - c[1][0], c[2][1] - c[1][1])) == pytest.approx(30.0)


def test_degenerate_inputs() -> None:
    assert_rect(min_area_rect([(1, 1), (1, 1)]), (1.0, 1.0), 0.0, 0.0, 0.0)
    assert_rect(
        min_area_rect([(0, 0), (3, 4), (6, 8)]),
        (3.0, 4.0),
        math.degrees(math.atan2(3, 4)),
        10.0,
        0.0,
    )
    with pytest.raises(NavError, match="at least one"):
        min_area_rect([])
    with pytest.raises(NavError, match="pair"):
        min_area_rect([(1, 2, 3)])


def _inside(r: Rect, p: tuple[float, float], tol: float) -> bool:
    (ax, ay), (nx, ny) = r.axes()
    dx, dy = p[0] - r.center_en[0], p[1] - r.center_en[1]
    return (
        abs(dx * ax + dy * ay) <= r.length_m / 2 + tol
        and abs(dx * nx + dy * ny) <= r.width_m / 2 + tol
    )


coords = st.floats(-100.0, 100.0, allow_nan=False).map(lambda x: round(x, 3))


@settings(max_examples=200, deadline=None)
@given(
    pts=st.lists(st.tuples(coords, coords), min_size=3, max_size=25),
    turn_deg=st.floats(0.0, 180.0),
)
def test_encloses_and_beats_any_rotated_bbox(
    pts: list[tuple[float, float]], turn_deg: float
) -> None:
    r = min_area_rect(pts)
    assert 0.0 <= r.long_axis_deg < 180.0
    assert r.length_m >= r.width_m >= 0.0
    assert all(_inside(r, p, 1e-7) for p in pts)
    t = math.radians(turn_deg)
    s, c = math.sin(t), math.cos(t)
    xs = [x * c - y * s for x, y in pts]
    ys = [x * s + y * c for x, y in pts]
    bbox = (max(xs) - min(xs)) * (max(ys) - min(ys))
    assert r.area_m2 <= bbox * (1 + 1e-9) + 1e-9
