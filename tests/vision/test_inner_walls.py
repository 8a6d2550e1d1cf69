"""`inner_walls` finds exactly the strips the plain numpy definition does: a pixel inside the
roof whose colour differs from the roof's by more than twice the tolerance (or the shade
given) in some channel,
of the roof's paint (its hue and saturation), touching no ground (its faster mask must not
move a single pixel)."""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt
from hypothesis import given, settings
from hypothesis import strategies as st

from uavtool.vision.shapes import Shape
from uavtool.vision.vectorize import ground_mask, inner_walls, roof_inside, same_paint

GROUND = (128, 128, 128)


def _reference(
    frame: npt.NDArray[np.uint8], shape: Shape, tolerance_dn: int, shade_dn: int | None
) -> list[np.ndarray]:
    """`inner_walls` as first written, with numpy's per-pixel maximum over the channels."""
    inside = roof_inside(frame, shape, inset_px=1, tolerance_dn=tolerance_dn)
    roof = np.array(shape.colour_rgb, np.int16)
    shade = 2 * tolerance_dn if shade_dn is None else shade_dn
    other = np.abs(frame.astype(np.int16) - roof).max(axis=2) > shade
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)
    roof_hsv = cv2.cvtColor(np.array([[shape.colour_rgb]], np.uint8), cv2.COLOR_RGB2HSV)[0, 0]
    if int(roof_hsv[1]) < 40:
        alike = hsv[:, :, 1] < 40
    else:
        d = np.abs(hsv[:, :, 0].astype(np.int16) - int(roof_hsv[0]))
        sat = hsv[:, :, 1].astype(np.int32)
        spread = (3 * 255 * 15) // np.maximum(hsv[:, :, 2].astype(np.int32), 1)
        alike = (
            (np.minimum(d, 180 - d) <= 8) & (sat >= 40) & (np.abs(sat - int(roof_hsv[1])) <= spread)
        )
    strips = (inside > 0) & other & alike
    ground = ground_mask(frame, tolerance_dn=tolerance_dn)
    near_ground = cv2.dilate(ground, np.ones((5, 5), np.uint8)) > 0
    count, labels = cv2.connectedComponents(strips.astype(np.uint8), connectivity=8)
    out = []
    for label in range(1, count):
        vs, us = np.nonzero(labels == label)
        if len(us) >= 3 and not near_ground[vs, us].any():
            out.append(np.stack([us, vs], axis=1).astype(np.int32))
    return out


_channel = st.integers(0, 255)


@settings(max_examples=60, deadline=None)
@given(
    roof=st.tuples(_channel, _channel, _channel),
    shade=st.tuples(_channel, _channel, _channel),
    step=st.integers(-40, 40),
    tolerance_dn=st.sampled_from([0, 1, 7, 15, 20, 60, 130]),
    shade_dn=st.sampled_from([None, 0, 15, 30, 100]),
    seed=st.integers(0, 2**32 - 1),
)
def test_inner_walls_are_those_of_the_numpy_definition(
    roof: tuple[int, int, int],
    shade: tuple[int, int, int],
    step: int,
    tolerance_dn: int,
    shade_dn: int | None,
    seed: int,
) -> None:
    frame = np.full((60, 80, 3), GROUND, np.uint8)
    frame[10:50, 10:70] = roof
    # a wall: the roof shaded by ``step`` (near the 2 * tolerance limit), and random pixels
    frame[20:40, 30:34] = np.clip(np.array(roof) + step, 0, 255)
    frame[25:30, 50:60] = shade
    noise = np.random.default_rng(seed).integers(0, 256, (10, 20, 3), dtype=np.uint8)
    frame[35:45, 40:60] = noise
    shape = Shape.from_rings(
        colour_rgb=roof,
        polygon_px=np.array([[10.0, 10.0], [69.0, 10.0], [69.0, 49.0], [10.0, 49.0]]),
    )
    got = inner_walls(frame, shape, tolerance_dn=tolerance_dn, shade_dn=shade_dn)
    want = _reference(frame, shape, tolerance_dn, shade_dn)
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_a_wall_whose_foot_stands_on_the_roof_is_kept_though_its_end_nears_the_ground() -> None:
    """With the photo's nadir known, a strip near the ground is dropped only when the ground
    lies at its foot (its side toward the nadir): a courtyard's far wall. A higher tier's
    wall whose end reaches the lower tier's edge stands on roof and is kept (town scene
    11921's stepped tower: without the nadir, both are dropped)."""
    roof, wall = (62, 51, 204), (49, 40, 162)
    frame = np.full((100, 100, 3), GROUND, np.uint8)
    frame[20:80, 20:80] = roof
    frame[21:60, 60:64] = wall  # a tier's wall, its upper end 2 px from the ground
    frame[40:56, 30:40] = GROUND  # a courtyard too narrow for the vectorizer's hole...
    frame[40:56, 26:30] = wall  # ... and its far wall, the courtyard's floor at its foot
    shape = Shape.from_rings(
        colour_rgb=roof,
        polygon_px=np.array([[20.0, 20.0], [79.0, 20.0], [79.0, 79.0], [20.0, 79.0]]),
    )
    assert inner_walls(frame, shape) == []
    kept = inner_walls(frame, shape, nadir_px=(95.0, 50.0))
    assert len(kept) == 1
    assert set(kept[0][:, 0].tolist()) == {60, 61, 62, 63}


def test_a_shade_is_its_paint_and_a_paint_of_the_same_hue_is_not() -> None:
    """Light scales every channel of a face alike, so a wall keeps its roof's hue and
    saturation, at any shade down to dark, with noise. A pale ground of the roof's hue
    (pink under a red roof) has the hue and not the saturation: not the roof's paint where
    it is bright enough for noise not to blur the two (in the dark, a channel's noise moves
    the saturation by more than they differ)."""
    rng = np.random.default_rng(3)
    red = (210, 40, 40)
    factors = np.repeat(np.linspace(0.3, 1.0, 64)[None, :, None], 16, axis=0)
    shades = factors * np.array(red, float)
    noisy = np.clip(shades + rng.normal(0.0, 3.0, shades.shape), 0, 255).astype(np.uint8)
    assert same_paint(noisy, red).all()
    pink = (np.linspace(0.8, 1.0, 64)[None, :, None] * np.array((150, 100, 95), float)).repeat(
        16, axis=0
    )
    assert not same_paint(pink.round().astype(np.uint8), red).any()
