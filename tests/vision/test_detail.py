"""What an outline leaves out (``Shape.detail_px``) and the outline tolerance it widens."""

from __future__ import annotations

import numpy as np

from uavtool.vision import Shape, VectorizeParams, vectorize
from uavtool.vision.io import shapes_from_json, shapes_to_json
from uavtool.vision.verify import (
    detail_differs,
    hides_detail,
    outline_accuracy_px,
    outline_tolerance,
)
from uavtool.world.raster import paint_polygon

RED = (210, 40, 40)
SLOTTED = [(60.0, 50.0), (150.0, 50.0), (150.0, 55.0), (155.0, 55.0), (155.0, 50.0),
           (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)]  # fmt: skip


def _one(ring: list[tuple[float, float]]) -> Shape:
    image = np.full((240, 320, 3), 128, np.uint8)
    paint_polygon(image, np.array(ring, dtype=np.float64), RED)
    (shape,) = vectorize(image, VectorizeParams())
    return shape


def test_paint_polygon_covers_the_pixels_whose_centres_are_inside() -> None:
    image = np.zeros((10, 10), np.uint8)
    paint_polygon(image, np.array([[1.0, 1.0], [6.0, 1.0], [6.0, 4.0], [1.0, 4.0]]), 1)
    assert int(image.sum()) == 5 * 3  # columns 1-5, rows 1-3
    assert image[1, 1] == 1 and image[4, 1] == 0 and image[1, 6] == 0


def test_a_clean_outline_leaves_out_no_more_than_its_pixels() -> None:
    shape = _one([(60.3, 50.2), (250.7, 70.9), (240.1, 180.4), (50.6, 160.8)])
    assert shape.detail_px < 1.5
    assert outline_accuracy_px(VectorizeParams()) == np.sqrt(0.5)


def test_a_notch_shorter_than_an_edge_kept_is_what_the_outline_left_out() -> None:
    """A 5 px slot in the long edge of a 190 px rectangle: its edges under ``min_edge_px``
    (8), so the outline keeps the plain rectangle and says it left out about the slot's
    depth."""
    ring = SLOTTED
    shape = _one(ring)
    assert len(shape.polygon_px) == 4
    assert 3.0 <= shape.detail_px <= 7.0
    clean = _one([(60.0, 50.0), (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)])
    accuracy = outline_accuracy_px(VectorizeParams())
    assert outline_tolerance(clean, shape, accuracy, accuracy) > outline_tolerance(
        clean, clean, accuracy, accuracy
    )


def test_a_notch_with_edges_longer_than_an_edge_kept_is_kept_at_any_angle() -> None:
    """A 12 px square notch in a corner of a 180 x 120 px rectangle (its edges half as long
    again as ``min_edge_px``), turned in 2.5° steps and shifted by fractions of a pixel: the
    outline keeps it (six corners) every time. RDP may split one of its edges in two
    where its staircase strays a little more than RDP's epsilon; those two pieces, each under
    ``min_edge_px``, are one straight edge, not two stubs to drop."""
    notched = [(70, 60), (238, 60), (238, 72), (250, 72), (250, 180), (70, 180)]
    for angle in np.arange(0.0, 90.0, 2.5):
        c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
        for shift in (0.0, 0.3, 0.6):
            ring = [
                (160 + (x - 160) * c - (y - 120) * s + shift, 120 + (x - 160) * s + (y - 120) * c)
                for x, y in notched
            ]
            assert len(_one(ring).polygon_px) == 6, (angle, shift)


def test_detail_survives_the_shapes_file() -> None:
    shape = _one(SLOTTED)
    (back,) = shapes_from_json(shapes_to_json((shape,), width_px=320, height_px=240))
    assert back.detail_px == shape.detail_px
    assert back.left_out_px == shape.left_out_px > 0.0


def test_a_line_of_wall_into_the_roof_is_no_detail_left_out() -> None:
    """The wall between two roofs of one building, seen as a dark line of its paint running
    into the roof from its edge: the roof's border follows it as a slit 40 px deep, but the
    building's own wall is the building. (What is left is the slit's mouth, a step of its
    width the outline kept.)"""
    image = np.full((240, 320, 3), 128, np.uint8)
    paint_polygon(
        image, np.array([(60.0, 50.0), (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)]), RED
    )
    wall = (120, 20, 20)  # the roof's paint, in shade
    paint_polygon(
        image, np.array([(150.0, 49.0), (152.0, 49.0), (152.0, 90.0), (150.0, 90.0)]), wall
    )
    # a photo from above, roofs only: the wall is no roof, and the roof's border runs into it
    (shape,) = [
        s for s in vectorize(image, VectorizeParams(roof_only=True)) if s.colour_rgb[0] > 180
    ]
    assert shape.detail_px < 4.0


def test_a_notch_the_target_picture_would_draw_is_not_judged_from_a_coarser_photo() -> None:
    """A 3 px slot is lost in the outline of a 190 px rectangle, which says it left out
    about 2 px: at most a corner cut with 4-5 px legs, under `min_edge_px` for a reference
    photo drawing it at the same scale, but up to ~14 px for one drawing it three times
    larger, which would keep it: from this photo the candidate is not judged against that
    reference. A candidate drawn larger than the reference hides nothing from it, whatever it
    left out: the reference, drawn smaller, leaves out as much."""
    slotted = _one([(60.0, 50.0), (150.0, 50.0), (150.0, 53.0), (153.0, 53.0), (153.0, 50.0),
                    (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)])  # fmt: skip
    min_edge = VectorizeParams().min_edge_px
    same_scale = _one([(60.0, 50.0), (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)])
    assert 1.5 <= slotted.detail_px <= 3.0
    assert not hides_detail(same_scale, slotted, min_edge)
    image = np.full((480, 680, 3), 128, np.uint8)
    paint_polygon(
        image, np.array([(30.0, 40.0), (600.0, 40.0), (600.0, 400.0), (30.0, 400.0)]), RED
    )
    (finer,) = vectorize(image, VectorizeParams())
    assert hides_detail(finer, slotted, min_edge)
    smaller = _one([(100.0, 80.0), (160.0, 80.0), (160.0, 120.0), (100.0, 120.0)])
    assert not hides_detail(smaller, _one(SLOTTED), min_edge)


def _turned(
    ring: list[tuple[float, float]], deg: float, scale: float, size: tuple[int, int]
) -> list[tuple[float, float]]:
    """``ring`` turned by ``deg`` and scaled by ``scale`` about its centre, put in the middle
    of a picture of ``size`` (width, height)."""
    pts = np.array(ring, dtype=np.float64)
    centre = pts.mean(axis=0)
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    turned = (pts - centre) @ np.array([[c, s], [-s, c]]) * scale
    placed = turned + np.array([size[0] / 2, size[1] / 2])
    return [(float(x), float(y)) for x, y in placed]


def _drawn(ring: list[tuple[float, float]], size: tuple[int, int]) -> Shape:
    image = np.full((size[1], size[0], 3), 128, np.uint8)
    paint_polygon(image, np.array(ring, dtype=np.float64), RED)
    (shape,) = vectorize(image, VectorizeParams())
    return shape


PLAIN = [(60.0, 50.0), (250.0, 50.0), (250.0, 170.0), (60.0, 170.0)]


def test_a_feature_one_outline_left_out_and_the_other_lacks_is_another_footprint() -> None:
    """A 5 px slot lost in the outline of a 190 px rectangle (left out, about its depth)
    against the plain rectangle, whose outline left out nothing beyond its pixels' staircase:
    were they one footprint, the plain photo would show the slot too. Either way round, and
    from a plain photo drawing it half as large again; two photos that both left the slot out
    are not told apart by it, nor are two plain ones."""
    slotted, plain = _one(SLOTTED), _one(PLAIN)
    assert len(slotted.polygon_px) == len(plain.polygon_px) == 4
    assert slotted.left_out_px > 2.0 and plain.left_out_px <= 1.0
    assert detail_differs(plain, slotted)
    assert detail_differs(slotted, plain)
    larger = _drawn(_turned(PLAIN, 0.0, 1.5, (480, 320)), (480, 320))
    assert detail_differs(larger, slotted)
    assert not detail_differs(slotted, _one(SLOTTED))
    assert not detail_differs(plain, larger)


def test_one_plain_footprint_differs_in_no_detail_at_any_turn_or_scale() -> None:
    """The plain rectangle drawn turned by any angle (7.5° steps) at 0.6-1.6 times the
    reference's scale, shifted by a fraction of a pixel: each outline's traced border lies
    within the pixel grid's staircase, so no photo shows a feature another lacks."""
    reference = _one(PLAIN)
    for deg in np.arange(0.0, 90.0, 7.5):
        for scale in (0.6, 1.0, 1.6):
            ring = [(x + 0.37, y + 0.61) for x, y in _turned(PLAIN, deg, scale, (480, 400))]
            candidate = _drawn(ring, (480, 400))
            assert not detail_differs(reference, candidate), (deg, scale, candidate.left_out_px)
            assert not detail_differs(candidate, reference), (deg, scale)
