"""The plane-geometry predicates behind rectangles and viewpoints."""

from __future__ import annotations

import math

import pytest

from uavtool.nav import NavError
from uavtool.nav.geometry import (
    as_points,
    convex_hull,
    point_polygon_distance,
    segment_polygon_distance,
    segments_intersect,
    triangle_hits_polygon,
)

SQUARE = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]


def test_convex_hull_drops_inner_and_collinear_points() -> None:
    pts = [(2.0, 0.0), *SQUARE, (2.0, 2.0), (4.0, 1.0), (0.0, 0.0)]
    assert convex_hull(pts) == SQUARE
    assert convex_hull([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]) == [(0.0, 0.0), (2.0, 2.0)]


def test_point_polygon_distance() -> None:
    assert point_polygon_distance((2.0, 2.0), SQUARE) == 0.0  # inside
    assert point_polygon_distance((7.0, 2.0), SQUARE) == 3.0
    assert point_polygon_distance((7.0, 8.0), SQUARE) == 5.0  # to the corner
    assert point_polygon_distance((3.0, 4.0), [(0.0, 0.0)]) == 5.0  # a post
    assert point_polygon_distance((1.0, 5.0), [(0.0, 0.0), (2.0, 0.0)]) == 5.0  # a segment


def test_segments_intersect_and_touch() -> None:
    assert segments_intersect((0, 0), (2, 2), (0, 2), (2, 0))
    assert segments_intersect((0, 0), (2, 0), (2, 0), (3, 5))  # shared end
    assert segments_intersect((0, 0), (4, 0), (1, 0), (2, 0))  # collinear overlap
    assert not segments_intersect((0, 0), (1, 0), (2, 0), (3, 0))
    assert segments_intersect((0, 0), (2, 2), (3, 0), (0, 3.1))


def test_triangle_hits_polygon() -> None:
    tri = [(0.0, 0.0), (10.0, 0.0), (5.0, 10.0)]
    assert triangle_hits_polygon(tri, [(4.0, 2.0), (6.0, 2.0), (5.0, 3.0)])  # inside the triangle
    assert triangle_hits_polygon(tri, [(-50.0, -50.0), (50.0, -50.0), (0.0, 50.0)])  # around it
    assert triangle_hits_polygon(tri, [(7.0, 5.0), (12.0, 5.0), (12.0, 8.0)])  # crossing an edge
    assert not triangle_hits_polygon(tri, [(9.0, 6.0), (12.0, 6.0), (12.0, 9.0)])
    assert triangle_hits_polygon(tri, [(5.0, 5.0)])  # a post in the way


def test_as_points_rejects_bad_rows() -> None:
    with pytest.raises(NavError, match=r"obs\[1\] is not finite"):
        as_points([(0, 0), (float("inf"), 1)], what="obs")


def test_segment_polygon_distance() -> None:
    square = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]
    assert segment_polygon_distance((-5.0, 2.0), (10.0, 2.0), square) == 0.0  # crosses it
    assert segment_polygon_distance((1.0, 1.0), (2.0, 2.0), square) == 0.0  # inside it
    assert segment_polygon_distance((-5.0, 7.0), (10.0, 7.0), square) == 3.0  # passes above
    assert segment_polygon_distance((7.0, 2.0), (9.0, 2.0), square) == 3.0  # ends before it
    # a corner nearest the middle of the segment, not its ends
    assert segment_polygon_distance((-2.0, 8.0), (8.0, -2.0), square) == pytest.approx(0.0)
    assert segment_polygon_distance((0.0, 10.0), (10.0, 0.0), square) == pytest.approx(
        math.sqrt(2.0)
    )
