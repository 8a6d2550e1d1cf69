"""Obstacle geometry: signed distances to prisms, checked against hand-computed values and shapely,
and a scene's buildings turned into prisms."""

from __future__ import annotations

import math
import random

import pytest
import shapely

from uavtool.errors import InputError
from uavtool.geo import geo_from_enu
from uavtool.sitl import SitlConfig
from uavtool.sitl.obstacles import ObstacleField, Prism, prism_distance_m
from uavtool.world import load_scene
from uavtool.world.obstacles import scene_obstacles

# 4 m east × 3 m north, 6 m high, with its south-west corner at home.
BOX = Prism("box", ((0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)), 0.0, 6.0)
# The roof of paper's red tunnel: a block resting 2.5 m up.
ARCH = Prism("red", ((7.5, -12.0), (10.0, -12.0), (10.0, -8.5), (7.5, -8.5)), 2.5, 5.0)
# An L: a 6 × 6 square without its north-east 3 × 3 quarter.
ELL_EN_M = ((0.0, 0.0), (6.0, 0.0), (6.0, 3.0), (3.0, 3.0), (3.0, 6.0), (0.0, 6.0))
ELL = Prism("ell", ELL_EN_M, 0.0, 2.0)


@pytest.mark.parametrize(
    ("point", "expected_m"),
    [
        ((2.0, 1.5, 3.0), -1.5),  # inside: 1.5 m to the south and north walls
        ((3.5, 1.5, 3.0), -0.5),  # inside, nearer the east wall
        ((2.0, 1.5, 5.8), -0.2),  # inside, just under the roof
        ((7.0, 7.0, 3.0), 5.0),  # outside the north-east corner: hypot(3, 4)
        ((-3.0, -4.0, 3.0), 5.0),  # outside the south-west corner, on the other side
        ((2.0, 1.0, 10.0), 4.0),  # above the roof
        ((-3.0, -4.0, 18.0), 13.0),  # above and beyond a corner: hypot(5, 12)
        ((7.0, 1.5, 10.0), 5.0),  # above and beyond the east wall's top edge: hypot(3, 4)
        ((4.0, 1.0, 2.0), 0.0),  # on the east wall
        ((2.0, 1.0, -1.0), 1.0),  # below the floor (underground)
    ],
)
def test_box_distances(point: tuple[float, float, float], expected_m: float) -> None:
    assert prism_distance_m(BOX, *point) == pytest.approx(expected_m, abs=1e-12)


@pytest.mark.parametrize(
    ("point", "expected_m"),
    [
        ((8.75, -10.25, 1.0), 1.5),  # in the tunnel, 1.5 m below its roof
        ((8.75, -10.25, 2.3), 0.2),  # in the tunnel, just below its roof
        ((8.75, -10.25, 3.0), -0.5),  # in the roof block, nearest its underside
        ((5.5, -10.25, 1.0), 2.5),  # beside and below: to its edge, hypot(2, 1.5)
        ((8.75, -10.25, 7.0), 2.0),  # above it
    ],
)
def test_overhang_distances(point: tuple[float, float, float], expected_m: float) -> None:
    assert prism_distance_m(ARCH, *point) == pytest.approx(expected_m, abs=1e-12)


def test_concave_footprint_notch_and_winding() -> None:
    # In the notch of the L: the nearer of the two inner walls.
    assert prism_distance_m(ELL, 5.0, 5.0, 1.0) == pytest.approx(2.0)
    assert prism_distance_m(ELL, 4.5, 5.0, 1.0) == pytest.approx(1.5)
    # Beyond the outer north-east corner of the short leg: to the corner (6, 3).
    assert prism_distance_m(ELL, 9.0, 7.0, 1.0) == pytest.approx(5.0)
    assert prism_distance_m(ELL, 4.0, 3.5, 1.0) == pytest.approx(0.5)  # above the short leg
    assert prism_distance_m(ELL, 1.0, 5.0, 1.0) == pytest.approx(-1.0)  # inside the tall leg
    clockwise = Prism("cw", tuple(reversed(ELL.footprint_en_m)), 0.0, 2.0)
    for point in ((5.0, 5.0, 1.0), (1.0, 5.0, 1.0), (-2.0, 7.0, 4.0)):
        assert prism_distance_m(clockwise, *point) == prism_distance_m(ELL, *point)


def _reference_m(prism: Prism, east: float, north: float, up: float) -> float:
    """The same distance from shapely's 2-D geometry and the extrusion rule."""
    polygon = shapely.Polygon(prism.footprint_en_m)
    point = shapely.Point(east, north)
    horizontal = polygon.exterior.distance(point)
    if polygon.contains(point):
        horizontal = -horizontal
    vertical = max(prism.base_m - up, up - prism.top_m)
    if horizontal > 0 and vertical > 0:
        return float(math.hypot(horizontal, vertical))
    return float(max(horizontal, vertical))


def test_field_matches_shapely_on_random_points() -> None:
    prisms = scene_obstacles(load_scene("paper"))
    field = ObstacleField(prisms)
    rng = random.Random(7)
    for _ in range(2000):
        e, n, u = rng.uniform(-25, 25), rng.uniform(-20, 20), rng.uniform(-1, 12)
        expected = min(_reference_m(p, e, n, u) for p in prisms)
        distance, nearest = field.nearest(e, n, u)
        assert distance == pytest.approx(expected, abs=1e-9)
        assert nearest is not None
        assert prism_distance_m(nearest, e, n, u) == pytest.approx(distance, abs=1e-12)


def test_empty_field() -> None:
    assert ObstacleField(()).nearest(0.0, 0.0, 0.0) == (math.inf, None)
    assert ObstacleField(()).first_above(0, 0, from_up_m=0, to_up_m=50, radius_m=0.4) is None


def test_first_above_finds_what_a_climb_would_touch() -> None:
    roof = Prism("roof", ((-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)), 6.0, 8.0)
    higher = Prism("higher", ((-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)), 9.0, 10.0)
    field = ObstacleField((higher, roof))
    climb = {"from_up_m": 0.0, "radius_m": 0.4}
    hit = field.first_above(0.0, 0.0, to_up_m=10.0, **climb)
    assert hit is not None
    assert hit[0] is roof  # the lowest underside, whatever the order
    assert field.first_above(0.0, 0.0, to_up_m=5.59, **climb) is None  # 5.59 + 0.4 < 6
    assert field.first_above(0.0, 0.0, to_up_m=5.61, **climb) is not None
    assert field.first_above(3.39, 0.0, to_up_m=10.0, **climb) is not None  # rim: 0.39 < 0.4
    assert field.first_above(3.41, 0.0, to_up_m=10.0, **climb) is None
    assert field.first_above(0.0, 0.0, from_up_m=8.3, to_up_m=8.3, radius_m=0.4) is not None


def test_prism_validation() -> None:
    with pytest.raises(InputError, match="3 vertices"):
        Prism("x", ((0.0, 0.0), (1.0, 0.0)), 0.0, 1.0)
    with pytest.raises(InputError, match="above base"):
        Prism("x", BOX.footprint_en_m, 2.0, 2.0)
    with pytest.raises(InputError, match="finite"):
        Prism("x", ((0.0, 0.0), (math.nan, 0.0), (1.0, 1.0)), 0.0, 1.0)
    with pytest.raises(InputError, match="body radius"):
        SitlConfig(endpoints=(), body_radius_m=0.0)


def test_scene_obstacles_one_prism_per_block() -> None:
    scene = load_scene("paper")
    prisms = scene_obstacles(scene)
    blocks = [(b.name, blk) for b in scene.buildings for blk in b.blocks]
    assert len(prisms) == len(blocks) == 9
    for prism, (name, block) in zip(prisms, blocks, strict=True):
        assert prism.name == name
        assert prism.footprint_en_m == block.footprint_enu_m
        assert (prism.base_m, prism.top_m) == (block.base_m, block.top_m)
    assert [p.base_m for p in prisms if p.name == "red"] == [0.0, 2.5, 0.0, 0.0, 3.0, 0.0]


def test_scene_obstacles_stay_on_the_map_around_another_home() -> None:
    scene = load_scene("paper")
    home = geo_from_enu(scene.home, 10.0, -5.0, 0.0)  # the vehicle starts 10 m E, 5 m S
    moved = scene_obstacles(scene, home=home)
    for a, b in zip(scene_obstacles(scene), moved, strict=True):
        for (e0, n0), (e1, n1) in zip(a.footprint_en_m, b.footprint_en_m, strict=True):
            assert (e1, n1) == pytest.approx((e0 - 10.0, n0 + 5.0), abs=1e-6)
        assert (b.base_m, b.top_m) == (a.base_m, a.top_m)
