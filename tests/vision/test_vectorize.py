from __future__ import annotations

import numpy as np
import pytest
import shapely

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.vision import VectorizeParams, vectorize
from uavtool.vision.errors import ImageError, VisionParamError
from uavtool.vision.vectorize import non_ground
from uavtool.world import render, scene_from_dict

from .synth import draw, family_shape, place

RED = (210, 40, 40)
BLUE = (40, 60, 210)
YELLOW = (230, 210, 40)


def _scene(noise: float = 0.0) -> np.ndarray:
    rect = place(family_shape("rect", 0.6, 0.3), angle_deg=0, size_px=160, centre=(150, 150))
    ell = place(family_shape("L", 1.0, 0.4), angle_deg=30, size_px=150, centre=(430, 170))
    tri = np.array([[300.0, 330.0], [420.0, 460.0], [250.0, 440.0]])
    hole = place(family_shape("rect", 1.0, 0.3), angle_deg=0, size_px=40, centre=(150, 150))
    return draw([(rect, BLUE), (ell, RED), (tri, YELLOW)], noise_sigma=noise, holes=[hole])


def test_finds_each_coloured_region_with_its_colour_corners_and_holes() -> None:
    shapes = vectorize(_scene())
    assert len(shapes) == 3
    by_colour = {s.colour_rgb: s for s in shapes}
    blue = next(s for c, s in by_colour.items() if c[2] > 150)
    red = next(s for c, s in by_colour.items() if c[0] > 150 and c[1] < 100)
    yellow = next(s for c, s in by_colour.items() if c[0] > 150 and c[1] > 150)
    assert len(blue.polygon_px) == 4
    assert len(blue.holes_px) == 1
    assert len(red.polygon_px) == 6
    assert len(yellow.polygon_px) in (3, 4)  # the acute corner may be split in two
    # Area: a 160×96 rectangle with a 40×40 hole, within a few percent.
    assert blue.area_px == pytest.approx(160 * 96 - 40 * 40, rel=0.03)
    assert blue.centroid_px == pytest.approx((150, 150), abs=1.0)
    assert not any(s.cut_by_border for s in shapes)
    # The kept colour is the region's colour (lit or shaded half), not the ground's.
    assert blue.colour_rgb in (BLUE, tuple(int(c * 0.85) for c in BLUE))


def test_noise_does_not_change_the_shapes() -> None:
    clean = vectorize(_scene())
    noisy = vectorize(_scene(noise=8.0))
    assert [len(s.polygon_px) for s in clean] == [len(s.polygon_px) for s in noisy]
    for a, b in zip(clean, noisy, strict=True):
        assert b.area_px == pytest.approx(a.area_px, rel=0.02)


def test_is_deterministic_bit_for_bit() -> None:
    frame = _scene(noise=8.0)
    a = vectorize(frame)
    b = vectorize(frame.copy())
    for s, t in zip(a, b, strict=True):
        assert s.polygon_px.tobytes() == t.polygon_px.tobytes()
        assert s.area_px == t.area_px


def test_flags_shapes_cut_by_the_border_and_drops_tiny_blobs() -> None:
    cut = np.array([[-20.0, 100.0], [100.0, 100.0], [100.0, 200.0], [-20.0, 200.0]])
    speck = np.array([[300.0, 300.0], [305.0, 300.0], [305.0, 305.0], [300.0, 305.0]])
    shapes = vectorize(draw([(cut, RED), (speck, BLUE)]))
    assert len(shapes) == 1
    assert shapes[0].cut_by_border


@pytest.mark.parametrize(("family", "corners"), [("L", 6), ("T", 8), ("U", 8)])
def test_edges_a_few_degrees_off_the_pixel_grid_give_no_extra_corners(
    family: str, corners: int
) -> None:
    # A slanted edge rasterises as long straight runs; RDP may keep a vertex where one run
    # ends near a corner, leaving a short edge a few degrees off the real one.
    for angle in (2.3, 2.9, 3.2, 3.5, 3.8, 4.1):
        for size in (260, 330):
            poly = place(
                family_shape(family, 0.7, 0.35), angle_deg=angle, size_px=size, centre=(320, 240)
            )
            shapes = vectorize(draw([(poly, BLUE)], shade=False))
            assert [len(s.polygon_px) for s in shapes] == [corners], (angle, size)


def test_palette_extracts_only_the_listed_colour() -> None:
    shapes = vectorize(_scene(noise=5.0), VectorizeParams(palette_rgb=(RED,)))
    assert len(shapes) == 1
    assert len(shapes[0].polygon_px) == 6


def test_grey_ground_alone_gives_no_shapes() -> None:
    assert vectorize(draw([], noise_sigma=10.0)) == ()


def test_bad_input_raises_one_line_errors() -> None:
    with pytest.raises(ImageError, match="uint8"):
        vectorize(np.zeros((10, 10), np.float32))  # type: ignore[arg-type]
    with pytest.raises(VisionParamError, match="rdp_epsilon_px"):
        VectorizeParams(rdp_epsilon_px=-1.0)
    with pytest.raises(VisionParamError, match="denoise_px"):
        VectorizeParams(denoise_px=4)
    with pytest.raises(VisionParamError, match="straight_tolerance_px"):
        VectorizeParams(straight_tolerance_px=-0.5)


def test_from_above_a_hole_showing_only_the_buildings_own_walls_is_no_hole() -> None:
    """With ``roof_only``, the darker shade of a roof's colour (a wall seen in perspective)
    is left out. A strip of wall inside a roof (a higher block's, seen from above) is not a
    courtyard: filled. A courtyard shows the ground: kept."""
    roof = np.array([[40, 40], [360, 40], [360, 260], [40, 260]], float)
    wall = np.array([[80, 200], [320, 200], [320, 214], [80, 214]], float)  # 14 px wide
    yard = np.array([[150, 80], [250, 80], [250, 150], [150, 150]], float)
    dark = tuple(int(c * 0.6) for c in RED)
    image = draw([(roof, RED), (wall, dark)], size=(400, 300), holes=[yard], shade=False)
    (shape,) = vectorize(image, VectorizeParams(roof_only=True))
    assert len(shape.holes_px) == 1
    assert shape.holes_px[0].min(axis=0) == pytest.approx((150, 80), abs=1.5)
    walled = draw([(roof, RED), (wall, dark)], size=(400, 300), shade=False)
    (plain,) = vectorize(walled, VectorizeParams(roof_only=True))
    assert plain.holes_px == ()
    assert plain.area_px == pytest.approx(320 * 220, rel=0.02)


def test_non_ground_finds_what_vectorize_leaves_out() -> None:
    """Grey and black are no building colours to vectorize (nor, where it shares a region's
    colour class, a darker shade); every one is a roof not on the ground for the obstacle map,
    the ground none."""
    scene = scene_from_dict(
        {
            "target": "red",
            "buildings": [
                {"name": "red", "color": [210, 40, 40],
                 "blocks": [{"footprint": [[-12, -4], [-6, -4], [-6, 2], [-12, 2]], "top_m": 5}]},
                {"name": "dark red", "color": [110, 20, 20],
                 "blocks": [{"footprint": [[4, -4], [10, -4], [10, 2], [4, 2]], "top_m": 5}]},
                {"name": "concrete", "color": [170, 170, 175],
                 "blocks": [{"footprint": [[-12, 6], [-6, 6], [-6, 12], [-12, 12]], "top_m": 8}]},
                {"name": "black", "color": [25, 25, 25],
                 "blocks": [{"footprint": [[4, 6], [10, 6], [10, 12], [4, 12]], "top_m": 3}]},
            ],
        }
    )  # fmt: skip
    k = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
    image = render(scene, CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), k)
    assert len(vectorize(image)) == 2  # the reds only: grey and black are no building colour
    roofs = non_ground(image)
    assert len(roofs) == 4
    # each roof where its building is: pixels grow east (u) and south (v) of the centre
    west_south = [s for s in roofs if s.centroid_px[0] < 320 and s.centroid_px[1] > 240]
    assert len(west_south) == 1 and west_south[0].colour_rgb[0] > 150  # the red roof
    assert all(not s.cut_by_border for s in roofs)
    assert non_ground(np.full((480, 640, 3), 128, np.uint8)) == ()


def test_non_ground_takes_a_region_one_or_two_pixels_thin() -> None:
    """A region two pixels high (a wall's edge seen end on, world scene 50078's tour) is
    looked at for what it holds besides its roof in its box grown to what the paint test
    takes: the survey once stopped with "image too small: 67x2"."""
    image = np.full((120, 160, 3), 90, np.uint8)
    image[50:52, 20:100] = (200, 40, 40)
    image[118:120, 20:100] = (200, 40, 40)  # at the frame's edge: the box cannot grow down
    image[80:100, 20:60] = (40, 40, 200)
    roofs = non_ground(image)
    assert any(s.colour_rgb == (40, 40, 200) for s in roofs)


def test_non_ground_finds_every_building_a_region_joins() -> None:
    """World scene 50124: a 3.4 m building of the ground's own hue (brighter), a car park
    it stands on the edge of and a building beyond it are one region of what is not
    ground. The region's roof is one of them; the others are roofs too, or the obstacle map
    has a hole where a building stands (a side photo was once flown 2.2 m from it)."""
    scene = scene_from_dict(
        {
            "target": "magenta",
            "ground": {
                "color": [107, 161, 195],
                "areas": [{"name": "car park", "color": [149, 148, 143],
                           "polygon": [[-2, -8], [14, -8], [14, 8], [-2, 8]]}],
            },
            "buildings": [
                {"name": "blue", "color": [54, 146, 217],
                 "blocks": [{"footprint": [[-10, -4], [0, -4], [0, 4], [-10, 4]], "top_m": 3.4}]},
                {"name": "magenta", "color": [217, 54, 171],
                 "blocks": [{"footprint": [[12, -3], [18, -3], [18, 3], [12, 3]], "top_m": 10}]},
            ],
        }
    )  # fmt: skip
    k = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
    pose = CameraPose((2.0, 0.0, 60.0), 0.0, -90.0)
    image = render(scene, pose, k)
    roofs = non_ground(image)
    for building in scene.buildings:
        (block,) = building.blocks
        corners = np.array([(x, y, block.top_m) for x, y in block.footprint_enu_m])
        drawn = shapely.Polygon(project(corners, pose, k)[:, :2])
        assert any(drawn.contains(shapely.Point(s.centroid_px)) for s in roofs), building.name
