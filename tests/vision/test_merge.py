from __future__ import annotations

import numpy as np

from uavtool.vision import Shape
from uavtool.vision.merge import merge_touching


def _rect(x0: float, y0: float, x1: float, y1: float, colour: tuple[int, int, int]) -> Shape:
    ring = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)
    return Shape.from_rings(colour_rgb=colour, polygon_px=ring)


def test_roofs_of_one_colour_within_the_gap_become_one_shape() -> None:
    a = _rect(0, 0, 100, 50, (197, 38, 38))
    b = _rect(103, 0, 150, 50, (197, 38, 38))  # 3 px away: a block of the same building
    (merged,) = merge_touching((a, b), gap_px=6.0)
    assert merged.area_px > a.area_px + b.area_px  # the strip of wall between is filled
    assert merged.polygon_px[:, 0].min() == 0.0 and merged.polygon_px[:, 0].max() == 150.0
    assert merge_touching((a, b), gap_px=2.0) == (a, b)  # further apart than the gap


def test_colour_tolerance_joins_noisy_roofs_and_keeps_other_colours_apart() -> None:
    a = _rect(0, 0, 100, 50, (197, 38, 38))
    b = _rect(103, 0, 150, 50, (199, 36, 41))  # 3 levels off, 3 px away: the same building
    c = _rect(0, 53, 100, 90, (133, 20, 60))  # crimson, 3 px away: another building
    d = _rect(300, 0, 350, 50, (196, 38, 38))  # red, far away: another building
    out = merge_touching((a, b, c, d), gap_px=6.0, colour_tolerance_dn=10.0)
    assert len(out) == 3
    assert out[0].colour_rgb == a.colour_rgb and out[0].area_px > a.area_px + b.area_px
    assert out[1] is c and out[2] is d  # untouched shapes keep their own colours
    assert merge_touching((a, b, c, d), gap_px=6.0) == (a, b, c, d)  # exact colours only
    assert len(merge_touching((a, b), gap_px=6.0, colour_tolerance_dn=2.0)) == 2


def test_a_wall_strip_is_no_courtyard() -> None:
    """From above, the wall around a higher block shows as a thin strip of another colour
    inside the lower roof: a hole thinner than the gap is filled; a courtyard is kept."""
    ring = np.array([[0, 0], [200, 0], [200, 120], [0, 120]], dtype=np.float64)
    strip = np.array([[40, 60], [160, 60], [160, 63], [40, 63]], dtype=np.float64)  # 3 px
    yard = np.array([[60, 20], [140, 20], [140, 50], [60, 50]], dtype=np.float64)  # 30 px
    roof = Shape.from_rings(colour_rgb=(197, 38, 38), polygon_px=ring, holes_px=(strip, yard))
    (out,) = merge_touching((roof,), gap_px=6.0)
    assert len(out.holes_px) == 1 and out.holes_px[0].min(axis=0).tolist() == [60.0, 20.0]
    assert out.area_px == roof.area_px + 120 * 3
    # the same for a strip left between two merged roofs
    a = _rect(0, 0, 100, 50, (197, 38, 38))
    b = _rect(103, 0, 150, 50, (197, 38, 38))
    (merged,) = merge_touching((a, b), gap_px=6.0)
    assert merged.holes_px == ()
    plain = Shape.from_rings(colour_rgb=(197, 38, 38), polygon_px=ring)
    assert merge_touching((plain,), gap_px=6.0) == (plain,)


def test_a_slit_into_one_roof_is_closed_and_a_wide_notch_kept() -> None:
    """The wall between two roofs of one building may show as a slit one or two pixels wide
    into its outline: closed like the gap between two roofs. A notch wider than the gap is
    part of the shape."""
    slit = np.array(
        [[0, 0], [200, 0], [200, 100], [101, 100], [101, 70], [99.5, 70], [99.5, 100], [0, 100]],
        dtype=np.float64,
    )
    (out,) = merge_touching(
        (Shape.from_rings(colour_rgb=(197, 38, 38), polygon_px=slit),), gap_px=6.0
    )
    assert len(out.polygon_px) == 4 and out.area_px == 200 * 100
    notch = slit.copy()
    notch[[3, 4], 0] = 110.0  # 10.5 px wide
    shape = Shape.from_rings(colour_rgb=(197, 38, 38), polygon_px=notch)
    assert merge_touching((shape,), gap_px=6.0) == (shape,)
