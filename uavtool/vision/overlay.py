"""Draw vectorized shapes over their frame: outlines and corner points, like the paper's
vectorized figures."""

from __future__ import annotations

import cv2
import numpy as np

from uavtool.vision.shapes import FloatArray, Shape
from uavtool.vision.vectorize import CvArray, U8Array

_SHIFT = 4  # sub-pixel drawing: coordinates in 1/16 px
_OUTLINE_RGB = (255, 255, 255)
_HOLE_RGB = (0, 255, 255)
_CORNER_RGB = (0, 0, 0)
_CUT_RGB = (255, 0, 255)


def draw_overlay(frame_rgb: U8Array, shapes: tuple[Shape, ...], *, scale: int = 2) -> U8Array:
    """A copy of the frame, enlarged ``scale`` times, with each shape's outline (magenta when
    cut by the border), holes (cyan), corner points, and its index at the centroid."""
    big: CvArray = cv2.resize(
        np.ascontiguousarray(frame_rgb),
        None,
        fx=scale,
        fy=scale,
        interpolation=cv2.INTER_NEAREST,
    )
    for index, shape in enumerate(shapes):
        colour = _CUT_RGB if shape.cut_by_border else _OUTLINE_RGB
        _ring(big, shape.polygon_px, colour, scale)
        for hole in shape.holes_px:
            _ring(big, hole, _HOLE_RGB, scale)
        u, v = shape.centroid_px
        org = (round((u + 0.5) * scale) - 6, round((v + 0.5) * scale) + 6)
        cv2.putText(big, str(index), org, cv2.FONT_HERSHEY_SIMPLEX, 0.6, (0, 0, 0), 3)
        cv2.putText(big, str(index), org, cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 255, 255), 1)
    return np.asarray(big, dtype=np.uint8)


def _ring(img: CvArray, ring_px: FloatArray, colour: tuple[int, int, int], scale: int) -> None:
    # Pixel centre (u, v) of the original is ((u + 0.5)·scale − 0.5) in the enlarged image.
    pts = np.round(((ring_px + 0.5) * scale - 0.5) * (1 << _SHIFT)).astype(np.int32)
    cv2.polylines(img, [pts], True, colour, 1, cv2.LINE_AA, _SHIFT)
    for p in pts:
        cv2.circle(img, (int(p[0]), int(p[1])), 3 << _SHIFT, _CORNER_RGB, -1, cv2.LINE_AA, _SHIFT)
        cv2.circle(img, (int(p[0]), int(p[1])), 2 << _SHIFT, colour, -1, cv2.LINE_AA, _SHIFT)
