"""Whether a viewer's image panel shows a given picture, judged from a screenshot of the panel.

Lichtblick's image panel draws the picture whole in its canvas, centred, its aspect ratio kept
(the camera's "fit"). So the area the picture must fill is known from the canvas's box in the
screenshot and the picture's size alone, whatever the panel shows; the picture, resized to that
area, is compared with it pixel by pixel: the mean absolute difference per channel (0-255).

Measured in Lichtblick's app (commit 66adecb99, a 1600 × 1000 window) on the five golden
recordings: 0.03-0.05 for the frame the panel should show; at least 8.6 for an earlier frame
of the same flight, 13.4 for another flight's (different) last frame and 57 for the target
picture in the camera's panel or the camera's frame in the target's. :data:`MAX_ERROR` lies
between: a swapped topic or a stale frame fails, the right one resampled by the GPU passes.
(The old check, the share of the panel's pixels with a colour of the picture, gave another
recording's frame 0.61-0.64 against a threshold of 0.4.)
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

MAX_ERROR = 3.0
"""The largest mean absolute difference (per pixel and channel, 0-255) of a panel that shows
the picture."""


def image_area(canvas: Sequence[float], width: int, height: int) -> tuple[int, int, int, int]:
    """``(left, top, right, bottom)`` of a ``width`` × ``height`` picture fitted whole, centred,
    in ``canvas`` (``x, y, width, height`` in the panel's screenshot)."""
    x, y, w, h = canvas
    scale = min(w / width, h / height)
    shown_w, shown_h = width * scale, height * scale
    left, top = x + (w - shown_w) / 2, y + (h - shown_h) / 2
    return round(left), round(top), round(left + shown_w), round(top + shown_h)


def shown_error(panel: np.ndarray, canvas: Sequence[float], picture: np.ndarray) -> float:
    """The mean absolute difference between the area of ``panel`` (RGB) where ``canvas`` would
    show ``picture`` (RGB) and the picture resized to it; infinite if the panel is too small to
    hold that area. The area's outermost pixels are left out: they blend with the background."""
    left, top, right, bottom = image_area(canvas, picture.shape[1], picture.shape[0])
    if min(left, top) < 0 or right > panel.shape[1] or bottom > panel.shape[0]:
        return float("inf")
    if right - left < 3 or bottom - top < 3:
        return float("inf")
    region = panel[top:bottom, left:right].astype(np.int32)
    # Linear, as a GPU samples a texture (the panel's WebGL draws the picture as one).
    expected = cv2.resize(
        np.asarray(picture, np.uint8), (right - left, bottom - top), interpolation=cv2.INTER_LINEAR
    ).astype(np.int32)
    inner = (slice(1, -1), slice(1, -1))
    return float(np.abs(region[inner] - expected[inner]).mean())
