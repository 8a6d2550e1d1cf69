"""From above, a roof is told from its walls by geometry, in any light: a low sun lights the
walls facing it brighter than the roof, and the roof is still what the vectorizer keeps."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import shapely

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.vision import VectorizeParams, vectorize
from uavtool.vision.vectorize import non_ground
from uavtool.world import Block, Building, Lighting, Scene, load_scene, render
from uavtool.world.render import add_noise

K = Intrinsics.from_hfov(width_px=640, height_px=480)
CAMERA = CameraPose((0.0, 0.0, 80.0), 0.0, -90.0)
GREEN = (59, 217, 54)
GREY = (200, 200, 200)
FOOTPRINT = ((8.0, 5.0), (20.0, 5.0), (20.0, 12.0), (8.0, 12.0))
TOP_M = 22.0


def _scene(colour: tuple[int, int, int], sun_az: float, sun_el: float) -> Scene:
    """One box north-east of the camera's nadir, so its west and south walls show, in the
    given light."""
    building = Building("b", colour, (Block(FOOTPRINT, 0.0, TOP_M),))
    return dataclasses.replace(
        load_scene("paper"),
        buildings=(building,),
        target="b",
        lighting=Lighting(sun_azimuth_deg=sun_az, sun_elevation_deg=sun_el, ambient=0.25),
    )


def _roof_drawn() -> shapely.Polygon:
    corners = np.array([(x, y, TOP_M) for x, y in FOOTPRINT])
    return shapely.Polygon(project(corners, CAMERA, K))


def _iou(a: shapely.Polygon, b: shapely.Polygon) -> float:
    return float(a.intersection(b).area / a.union(b).area)


# A wall facing a sun 45° up is lit exactly as the roof is (Lambert: cos 45° = sin 45°): no
# shade tells them apart, and they are one region. The two walls this test sees face south
# and west.
LIGHTS = [
    (az, el)
    for el in (8.0, 20.0, 45.0, 70.0, 90.0)
    for az in (0.0, 90.0, 180.0, 225.0, 270.0)
    if not (el == 45.0 and az in (180.0, 270.0))
]


@pytest.mark.parametrize(("sun_az", "sun_el"), LIGHTS)
def test_the_roof_is_kept_and_its_walls_dropped_in_any_light(sun_az: float, sun_el: float) -> None:
    image = render(_scene(GREEN, sun_az, sun_el), CAMERA, K)
    (shape,) = vectorize(image, VectorizeParams(roof_only=True))
    assert _iou(shapely.Polygon(shape.polygon_px), _roof_drawn()) > 0.95


def test_a_low_sun_lights_the_walls_brighter_than_the_roof() -> None:
    """What the test above stands on: from the west 8° up, the west wall is brighter than the
    roof, so the brightest shade is a wall."""
    image = render(_scene(GREEN, 270.0, 8.0), CAMERA, K).astype(int)
    roof = _roof_drawn().centroid
    u, v = round(roof.x), round(roof.y)
    west_wall = project(np.array([(8.0, 8.5, TOP_M / 2)]), CAMERA, K)[0]
    assert image[round(west_wall[1]), round(west_wall[0])].sum() > image[v, u].sum() + 100


@pytest.mark.parametrize(("sun_az", "sun_el"), [(270.0, 8.0), (180.0, 20.0), (0.0, 90.0)])
def test_an_obstacles_roof_is_its_roof_in_any_light(sun_az: float, sun_el: float) -> None:
    """A grey roof (no hue: an obstacle, never a candidate) is found the same way."""
    image = render(_scene(GREY, sun_az, sun_el), CAMERA, K)
    (shape,) = non_ground(image)
    assert _iou(shapely.Polygon(shape.polygon_px), _roof_drawn()) > 0.95


# Lights under which the walls this test sees are lit 12–20 DN off the roof (V 163–179):
# close enough that a fixed tolerance of 20 DN took them for roof, as far as a noise-free
# photo tells them apart.
LIT_WALLS = [(180.0, 42.0), (270.0, 42.0), (180.0, 50.0), (270.0, 50.0)]


@pytest.mark.parametrize(("sun_az", "sun_el"), LIT_WALLS)
def test_walls_lit_near_the_roofs_shade_are_not_roof(sun_az: float, sun_el: float) -> None:
    """A flat roof is one shade: in a photo without noise a wall a few DN off it is a wall,
    and the outline lies on the roof's edges within the vectorizer's accuracy (half a
    pixel's diagonal), not a wall's width (24 px here) outside them."""
    image = render(_scene(GREEN, sun_az, sun_el), CAMERA, K)
    (shape,) = vectorize(image, VectorizeParams(roof_only=True))
    gap = shapely.hausdorff_distance(shapely.Polygon(shape.polygon_px), _roof_drawn())
    assert gap <= math.sqrt(0.5)


@pytest.mark.parametrize(("sun_az", "sun_el"), [*LIT_WALLS, (0.0, 90.0), (270.0, 8.0)])
def test_sensor_noise_leaves_the_roof_whole(sun_az: float, sun_el: float) -> None:
    """With the sensor's noise (σ 3 DN) the roof's own shade spreads, and so does what counts
    as roof: none of the roof is lost to the noise."""
    image = render(_scene(GREEN, sun_az, sun_el), CAMERA, K)
    add_noise(image, seed=7)
    (shape,) = vectorize(image, VectorizeParams(roof_only=True))
    roof = _roof_drawn()
    assert roof.difference(shapely.Polygon(shape.polygon_px)).area < 0.005 * roof.area
