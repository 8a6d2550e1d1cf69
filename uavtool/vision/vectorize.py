"""Vectorization (paper III-A): colour filtering, borders, evenly spaced points, RDP.

``vectorize(frame_rgb, params)`` is pure: the same frame and parameters give bit-identical
shapes on any machine. OpenCV does the integer work (HSV, masks, contour tracing) and is run
single-threaded; everything after the contour is IEEE float64 arithmetic in a fixed order.
"""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.vision.corners import refine_corners
from uavtool.vision.errors import ImageError
from uavtool.vision.params import VectorizeParams
from uavtool.vision.rdp import rdp_ring_indices
from uavtool.vision.shapes import FloatArray, Shape, orient

U8Array = npt.NDArray[np.uint8]
# What OpenCV returns (its stubs type every array loosely).
CvArray = npt.NDArray[Any]

# OpenCV's full-range HSV: hue 0–255 covers the 360° circle.
_HUE_BINS = 256
_DEG_PER_BIN = 360.0 / _HUE_BINS
# A run of occupied hue bins may have gaps this wide and still be one colour.
_MAX_GAP_BINS = 2
# Mitre joins of the edge offset are clamped to this many offsets (spikes at sharp turns).
_MAX_MITRE = 3.0


def vectorize(frame_rgb: U8Array, params: VectorizeParams | None = None) -> tuple[Shape, ...]:
    """The coloured regions of an RGB frame ``(h, w, 3) uint8`` as shapes.

    Shapes are ordered by palette colour, then by area (largest first). Raises
    :class:`ImageError` for anything but an ``(h, w, 3)`` uint8 array.
    """
    p = params if params is not None else VectorizeParams()
    frame = _check_frame(frame_rgb)
    cv2.setNumThreads(1)
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV_FULL)
    valid = cv2.inRange(hsv, (0, p.min_saturation, p.min_value), (255, 255, 255))
    lut = hue_lut(hsv, valid, p)
    n_classes = int(lut.max())
    if n_classes == 0:
        return ()
    classes = cv2.bitwise_and(cv2.LUT(cv2.extractChannel(hsv, 0), lut), valid)
    if p.denoise_px > 1:
        # The median of class ids is always one of the ids present, so no class is invented.
        classes = cv2.medianBlur(classes, p.denoise_px)
    shapes: list[Shape] = []
    for k in range(1, n_classes + 1):
        mask = cv2.inRange(classes, k, k)
        if p.roof_only:
            mask = _brightest_shade(hsv, mask, p)
        found = _shapes_in_mask(frame, mask, p)
        shapes.extend(sorted(found, key=lambda s: -s.area_px))
    return tuple(shapes)


def hue_lut(hsv: CvArray, valid: CvArray, params: VectorizeParams) -> U8Array:
    """A 256-entry table from full-range hue to colour class (0 = none, 1…k).

    With a palette, class ``i+1`` is the hues within the tolerance of palette colour ``i``
    (the nearest colour wins where windows overlap). Without one, each circular run of
    occupied hue-histogram bins holding at least ``min_area_px`` pixels is a class.
    """
    lut = np.zeros(_HUE_BINS, dtype=np.uint8)
    if params.palette_rgb:
        best = np.full(_HUE_BINS, np.inf)
        bins = np.arange(_HUE_BINS, dtype=np.float64)
        for i, colour in enumerate(params.palette_rgb):
            centre = float(hue_of(colour)) / _DEG_PER_BIN
            d = np.abs(bins - centre)
            d = np.minimum(d, _HUE_BINS - d) * _DEG_PER_BIN
            take = (d <= params.hue_tolerance_deg) & (d < best)
            lut[take] = i + 1
            best[take] = d[take]
        return lut
    hist = cv2.calcHist([hsv], [0], valid, [_HUE_BINS], [0, _HUE_BINS]).ravel()
    occupied = hist >= max(2.0, params.min_area_px / 50.0)
    if not occupied.any():
        return lut
    if occupied.all():
        lut[:] = 1
        return lut
    # Start the circular scan at an empty bin so no run wraps around the start.
    start = int(np.argmin(occupied))
    runs: list[list[int]] = []
    gap = _MAX_GAP_BINS + 1
    for step in range(_HUE_BINS):
        b = (start + step) % _HUE_BINS
        if occupied[b]:
            if gap > _MAX_GAP_BINS:
                runs.append([])
            runs[-1].extend(range(b - gap, b) if gap <= _MAX_GAP_BINS else ())
            runs[-1].append(b)
            gap = 0
        else:
            gap += 1
    k = 0
    for run in runs:
        idx = [b % _HUE_BINS for b in run]
        if math.fsum(hist[idx].tolist()) >= params.min_area_px:
            k += 1
            lut[idx] = k
    return lut


def _brightest_shade(hsv: CvArray, mask: CvArray, p: VectorizeParams) -> CvArray:
    """The part of ``mask`` in the brightest shade of its colour.

    Flat shading gives each face orientation one brightness; a roof faces the sky and is
    brighter than every wall, so from above this keeps the roofs and drops the walls that
    perspective shows around them.
    """
    hist = cv2.calcHist([hsv], [2], mask, [256], [0, 256]).ravel()
    total = float(hist.sum())
    if total == 0.0:
        return mask
    # The brightest value holding a real share of the pixels (not a few noisy ones).
    cum = np.cumsum(hist[::-1])
    top = 255 - int(np.argmax(cum >= max(p.min_area_px, 0.02 * total)))
    bright = cv2.inRange(cv2.extractChannel(hsv, 2), max(0, top - p.roof_value_tolerance), 255)
    return cv2.bitwise_and(mask, bright)


def hue_of(colour_rgb: tuple[int, int, int]) -> int:
    """Full-range (0–255) OpenCV hue of one RGB colour."""
    px = np.array([[colour_rgb]], dtype=np.uint8)
    return int(cv2.cvtColor(px, cv2.COLOR_RGB2HSV_FULL)[0, 0, 0])


def hue_distance_deg(a_rgb: tuple[int, int, int], b_rgb: tuple[int, int, int]) -> float:
    """Circular hue difference of two colours, degrees in [0, 180]."""
    d = abs(hue_of(a_rgb) - hue_of(b_rgb))
    return min(d, _HUE_BINS - d) * _DEG_PER_BIN


def _check_frame(frame_rgb: U8Array) -> U8Array:
    arr = np.asarray(frame_rgb)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.dtype != np.uint8:
        raise ImageError(f"expected an (h, w, 3) uint8 RGB image, got {arr.shape} {arr.dtype}")
    if arr.shape[0] < 3 or arr.shape[1] < 3:
        raise ImageError(f"image too small: {arr.shape[1]}x{arr.shape[0]}")
    return np.ascontiguousarray(arr)


def _shapes_in_mask(frame: U8Array, mask: CvArray, p: VectorizeParams) -> list[Shape]:
    contours, hierarchy = cv2.findContours(mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
    if len(contours) == 0:
        return []
    h, w = mask.shape
    tree = hierarchy[0]
    shapes: list[Shape] = []
    for i, contour in enumerate(contours):
        if tree[i][3] != -1:
            continue  # a hole; handled with its parent
        if cv2.contourArea(contour) + 0.5 * len(contour) < p.min_area_px:
            continue
        pts = contour[:, 0, :]
        cut = bool(
            (pts[:, 0] == 0).any()
            or (pts[:, 1] == 0).any()
            or (pts[:, 0] == w - 1).any()
            or (pts[:, 1] == h - 1).any()
        )
        holes: list[FloatArray] = []
        child = int(tree[i][2])
        while child != -1:
            hole = contours[child]
            if cv2.contourArea(hole) - 0.5 * len(hole) >= p.min_hole_area_px:
                ring = _simplify(hole[:, 0, :], p)
                if len(ring) >= 3:
                    holes.append(ring)
            child = int(tree[child][0])
        outer = _simplify(pts, p)
        if len(outer) < 3:
            continue
        shape = _offset_shape(outer, tuple(holes), cut, p.edge_offset_px)
        colour = _inside_colour(frame, mask, contour, shape)
        shapes.append(
            Shape(colour, shape.polygon_px, shape.holes_px, shape.area_px, shape.centroid_px, cut)
        )
    return shapes


def _simplify(contour_px: CvArray, p: VectorizeParams) -> FloatArray:
    """Evenly spaced points along a closed pixel contour, then RDP, then corner refinement."""
    dense = resample_ring(contour_px.astype(np.float64), p.point_spacing_px)
    kept = rdp_ring_indices(dense, p.rdp_epsilon_px)
    if not p.refine_corners:
        out: FloatArray = dense[kept]
        return out
    return refine_corners(
        dense,
        kept.tolist(),
        min_edge_px=p.min_edge_px,
        max_shift_px=p.min_edge_px + p.point_spacing_px + p.rdp_epsilon_px,
    )


def resample_ring(ring_px: FloatArray, spacing_px: float) -> FloatArray:
    """Points every ``spacing_px`` (adjusted to divide the length evenly) along a closed ring."""
    closed = np.concatenate([ring_px, ring_px[:1]])
    d = np.diff(closed, axis=0)
    seg = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = float(cum[-1])
    n = max(3, round(total / spacing_px))
    if total == 0.0:
        return ring_px[:1].copy()
    s = np.arange(n, dtype=np.float64) * (total / n)
    return np.stack([np.interp(s, cum, closed[:, 0]), np.interp(s, cum, closed[:, 1])], axis=1)


def offset_ring(ring_px: FloatArray, offset_px: float) -> FloatArray:
    """Move every edge of a ring by ``offset_px`` along its normal ``(dy, −dx)``.

    For the orientations :class:`Shape` uses (outer ring positive, holes negative) this
    moves every edge away from the filled region.
    """
    if offset_px == 0.0 or len(ring_px) < 3:
        return ring_px
    d_next = np.concatenate([ring_px[1:], ring_px[:1]]) - ring_px
    length = np.sqrt(d_next[:, 0] * d_next[:, 0] + d_next[:, 1] * d_next[:, 1])
    length[length == 0.0] = 1.0
    normal = np.stack([d_next[:, 1] / length, -d_next[:, 0] / length], axis=1)
    n_prev = np.concatenate([normal[-1:], normal[:-1]])
    dot = normal[:, 0] * n_prev[:, 0] + normal[:, 1] * n_prev[:, 1]
    # Intersection of the two moved edge lines: offset · (n1 + n2) / (1 + n1·n2).
    denom = np.maximum(1.0 + dot, 2.0 / (_MAX_MITRE * _MAX_MITRE))
    scale = offset_px / denom
    out: FloatArray = ring_px + (normal + n_prev) * scale[:, None]
    return out


def _offset_shape(
    outer: FloatArray, holes: tuple[FloatArray, ...], cut: bool, offset_px: float
) -> Shape:
    outer = orient(outer, positive=True)
    holes = tuple(orient(h, positive=False) for h in holes)
    return Shape.from_rings(
        colour_rgb=(0, 0, 0),
        polygon_px=offset_ring(outer, offset_px),
        holes_px=tuple(offset_ring(h, offset_px) for h in holes),
        cut_by_border=cut,
    )


def _inside_colour(
    frame: U8Array, mask: CvArray, contour: CvArray, shape: Shape
) -> tuple[int, int, int]:
    """Median RGB of the region's pixels in the 3×3 window around a pixel inside it."""
    h, w = mask.shape
    u, v = round(shape.centroid_px[0]), round(shape.centroid_px[1])
    inside = (
        0 <= u < w
        and 0 <= v < h
        and mask[v, u] != 0
        and cv2.pointPolygonTest(contour, (float(u), float(v)), False) > 0
    )
    if not inside:
        u, v = _deepest_pixel(mask, contour)
    v0, v1, u0, u1 = max(v - 1, 0), min(v + 2, h), max(u - 1, 0), min(u + 2, w)
    window = frame[v0:v1, u0:u1][mask[v0:v1, u0:u1] != 0]
    if len(window) == 0:
        window = frame[v : v + 1, u]
    med = np.sort(window, axis=0)[(len(window) - 1) // 2]
    return (int(med[0]), int(med[1]), int(med[2]))


def _deepest_pixel(mask: CvArray, contour: CvArray) -> tuple[int, int]:
    """The pixel of the contour's region farthest from its border."""
    x, y, bw, bh = cv2.boundingRect(contour)
    region = np.zeros((bh + 2, bw + 2), dtype=np.uint8)
    cv2.drawContours(region, [contour], 0, 255, thickness=cv2.FILLED, offset=(1 - x, 1 - y))
    inside = cv2.bitwise_and(
        region,
        cv2.copyMakeBorder(mask[y : y + bh, x : x + bw], 1, 1, 1, 1, cv2.BORDER_CONSTANT, value=0),
    )
    dist = cv2.distanceTransform(inside, cv2.DIST_L2, 3)
    k = int(np.argmax(dist))
    return (k % (bw + 2) + x - 1, k // (bw + 2) + y - 1)
