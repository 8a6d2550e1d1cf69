from __future__ import annotations

import numpy as np
import pytest

from uavtool.camera import CameraPose, Intrinsics
from uavtool.vision import vectorize
from uavtool.vision.errors import ShapeFileError
from uavtool.vision.io import shapes_from_json, shapes_to_json, views_from_json, views_to_json

from .synth import draw, family_shape, place


def test_shapes_round_trip_exactly() -> None:
    frame = draw(
        [
            (
                place(family_shape("U", 0.8, 0.35), angle_deg=17, size_px=150, centre=(200, 200)),
                (40, 90, 220),
            ),
            (
                place(family_shape("rect", 0.6, 0.3), angle_deg=0, size_px=160, centre=(460, 300)),
                (210, 40, 40),
            ),
        ],
        holes=[place(family_shape("rect", 1.0, 0.3), angle_deg=0, size_px=30, centre=(460, 300))],
    )
    shapes = vectorize(frame)
    back = shapes_from_json(shapes_to_json(shapes, width_px=640, height_px=480))
    assert len(back) == len(shapes) == 2
    for a, b in zip(shapes, back, strict=True):
        assert a.colour_rgb == b.colour_rgb
        assert np.array_equal(a.polygon_px, b.polygon_px)
        assert len(a.holes_px) == len(b.holes_px)
        for h, k in zip(a.holes_px, b.holes_px, strict=True):
            assert np.array_equal(h, k)
        assert (a.area_px, a.centroid_px, a.cut_by_border) == (
            b.area_px,
            b.centroid_px,
            b.cut_by_border,
        )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", r"shapes.json:1: invalid JSON"),
        ('{"format": "x", "version": 1}', "not a uavtool.shapes file"),
        (
            '{"format": "uavtool.shapes", "version": 1, "shapes": [{}]}',
            r"shapes\[0\]: missing field 'colour_rgb'",
        ),
        (
            '{"format": "uavtool.shapes", "version": 1, "shapes": [{"colour_rgb": [1,2,3],'
            ' "polygon_px": [[0,0],[1,1]], "holes_px": []}]}',
            r"shapes\[0\].polygon_px: expected at least 3",
        ),
    ],
)
def test_bad_shape_files_say_what_and_where(text: str, message: str) -> None:
    with pytest.raises(ShapeFileError, match=message):
        shapes_from_json(text, source="shapes.json")


def test_poses_round_trip_and_errors() -> None:
    k = Intrinsics.from_hfov(hfov_deg=70.0)
    views = {n: (CameraPose((1.0, 2.0, 3.0), 45.0, -90.0), k) for n in ("top", "front", "right")}
    back, ground = views_from_json(views_to_json(views, 1.5))
    assert back == views
    assert ground == 1.5
    with pytest.raises(ShapeFileError, match=r"poses\.json: top: missing"):
        views_from_json("{}", source="poses.json")
    bad = '{"top": {"pos_enu_m": [0, 0], "heading_deg": 0, "pitch_deg": -90, "intrinsics": {}}}'
    with pytest.raises(ShapeFileError, match="top: pos_enu_m needs 3 values"):
        views_from_json(bad)
    hfov = (
        '{"top": {"pos_enu_m": [0, 0, 9], "heading_deg": 0, "pitch_deg": -90,'
        ' "intrinsics": {"width_px": 640, "height_px": 480, "hfov_deg": 200}}}'
    )
    with pytest.raises(ShapeFileError, match="top: camera horizontal FOV"):
        views_from_json(hfov)
