"""Colour classes for vectorization: which hues make a building colour, and roof shades.

Work is on OpenCV's full-range HSV (hue 0–255 covers the 360° circle); every decision is on
integer pixel counts, so it is the same on every machine.
"""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.vision.params import VectorizeParams

U8Array = npt.NDArray[np.uint8]
# What OpenCV returns (its stubs type every array loosely).
CvArray = npt.NDArray[Any]

HUE_BINS = 256
_DEG_PER_BIN = 360.0 / HUE_BINS
# A run of occupied hue bins may have gaps this wide and still be one colour.
_MAX_GAP_BINS = 2


def hue_lut(hue: CvArray, valid: CvArray, params: VectorizeParams) -> U8Array:
    """A 256-entry table from full-range hue to colour class (0 = none, 1…k).

    ``hue`` : (h, w) uint8 hue channel; ``valid`` : (h, w) uint8 mask of the pixels saturated
    and bright enough to have a hue. With a palette, class ``i+1`` is the hues within the
    tolerance of palette colour ``i`` (the nearest colour wins where windows overlap).
    Without one, each circular run of occupied hue-histogram bins holding at least
    ``min_area_px`` pixels is a class, numbered from the first empty bin.
    """
    lut = np.zeros(HUE_BINS, dtype=np.uint8)
    if params.palette_rgb:
        best = np.full(HUE_BINS, np.inf)
        bins = np.arange(HUE_BINS, dtype=np.float64)
        for i, colour in enumerate(params.palette_rgb):
            centre = float(hue_of(colour)) / _DEG_PER_BIN
            d = np.abs(bins - centre)
            d = np.minimum(d, HUE_BINS - d) * _DEG_PER_BIN
            take = (d <= params.hue_tolerance_deg) & (d < best)
            lut[take] = i + 1
            best[take] = d[take]
        return lut
    hist = cv2.calcHist([hue], [0], valid, [HUE_BINS], [0, HUE_BINS]).ravel()
    occupied = hist >= max(2.0, params.min_area_px / 50.0)
    if not occupied.any():
        return lut
    if occupied.all():
        lut[:] = 1
        return lut
    # Scan the circle from an empty bin so no run wraps around the start. A run is a
    # stretch of occupied bins with gaps of at most _MAX_GAP_BINS (the gaps belong to it).
    start = int(np.argmin(occupied))
    order = (start + np.arange(HUE_BINS)) % HUE_BINS
    pos = np.flatnonzero(occupied[order])
    breaks = np.flatnonzero(np.diff(pos) > _MAX_GAP_BINS + 1)
    firsts = [int(pos[0]), *pos[breaks + 1].tolist()]
    lasts = [*pos[breaks].tolist(), int(pos[-1])]
    counts = hist[order].tolist()
    k = 0
    for first, last in zip(firsts, lasts, strict=True):
        if math.fsum(counts[first : last + 1]) >= params.min_area_px:
            k += 1
            lut[order[first : last + 1]] = k
    return lut


def brightest_shade(value: CvArray, mask: CvArray, params: VectorizeParams) -> CvArray:
    """The part of ``mask`` in the brightest shade of its colour (``value`` : HSV V channel).

    Flat shading gives each face orientation one brightness; a roof faces the sky and is
    brighter than every wall, so from above this keeps the roofs and drops the walls that
    perspective shows around them.
    """
    hist = cv2.calcHist([value], [0], mask, [256], [0, 256]).ravel()
    total = float(hist.sum())
    if total == 0.0:
        return mask
    # The brightest value holding a real share of the pixels (not a few noisy ones).
    cum = np.cumsum(hist[::-1])
    top = 255 - int(np.argmax(cum >= max(params.min_area_px, 0.02 * total)))
    bright = cv2.threshold(value, max(0, top - params.roof_value_tolerance) - 1, 255, 0)[1]
    return cv2.bitwise_and(mask, bright)


def hue_of(colour_rgb: tuple[int, int, int]) -> int:
    """Full-range (0–255) OpenCV hue of one RGB colour."""
    px = np.array([[colour_rgb]], dtype=np.uint8)
    return int(cv2.cvtColor(px, cv2.COLOR_RGB2HSV_FULL)[0, 0, 0])


def has_hue(colour_rgb: tuple[int, int, int], params: VectorizeParams) -> bool:
    """Whether a colour is one :func:`uavtool.vision.vectorize` classes by hue: saturated
    and bright enough (``min_saturation``, ``min_value``), not a grey, white or black."""
    px = np.array([[colour_rgb]], dtype=np.uint8)
    _h, s, v = (int(c) for c in cv2.cvtColor(px, cv2.COLOR_RGB2HSV_FULL)[0, 0])
    return s >= params.min_saturation and v >= params.min_value


def hue_distance_deg(a_rgb: tuple[int, int, int], b_rgb: tuple[int, int, int]) -> float:
    """Circular hue difference of two colours, degrees in [0, 180]."""
    d = abs(hue_of(a_rgb) - hue_of(b_rgb))
    return min(d, HUE_BINS - d) * _DEG_PER_BIN
