"""Heights from parallax: how high the things inside a roof's outline stand.

A roof's outline, matched between two nadir photos, gives one height (the plane that carries
one outline onto the other). A stepped tower whose tiers share a colour has the outline of its
lowest tier from above: its upper tiers show only as edges inside that outline (the walls
between the tiers). Each such edge lies on some plane z = h, and only at that height does the
plane's homography carry the other photo's pixels onto it: a plane sweep over heights finds,
for every inner edge pixel, the height at which the two photos agree there. The highest of
them bounds the building's top from below — evidence that the roof is not flat.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.nav.errors import NavError
from uavtool.nav.projection import ground_point

_WINDOW_PX = 5
"""The side of the square window compared between the photos around each edge pixel."""
_EDGE_DN = 12.0
"""The least brightness step (grey levels, over the window's centre) that counts as an edge;
the renderer's flat roofs vary by a few levels, a wall beside a roof by tens."""
_UNIQUE = 0.5
"""An edge pixel's best height must fit at least this much better than the typical height
(cost at most this share of the median): an edge along the direction the heights move
things fits every height alike and says nothing."""
_MIN_EDGE_PX = 8
"""The fewest agreeing edge pixels that make a top (fewer is noise)."""
_TOP_SHARE = 0.1
"""The top is the height that this share of the agreeing edge pixels reach or pass."""


def highest_inner_edge_m(
    image_b: np.ndarray,
    pose_b: CameraPose,
    roof_b: np.ndarray,
    image_a: np.ndarray,
    pose_a: CameraPose,
    intrinsics: Intrinsics,
    *,
    lo_m: float,
    hi_m: float,
    step_m: float = 0.5,
) -> float | None:
    """The height (above home) that the edges in ``roof_b`` (a mask of one roof's inside in
    photo B) reach, found by a plane sweep against photo A from ``lo_m`` to ``hi_m``; None
    when the roof holds too few edges that the two photos place at one height."""
    k = intrinsics
    grey_b = cv2.cvtColor(np.ascontiguousarray(image_b), cv2.COLOR_RGB2GRAY).astype(np.float32)
    grey_a = cv2.cvtColor(np.ascontiguousarray(image_a), cv2.COLOR_RGB2GRAY).astype(np.float32)
    inside = roof_b
    gx = cv2.Sobel(grey_b, cv2.CV_32F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(grey_b, cv2.CV_32F, 0, 1, ksize=3) / 8.0
    edges = (np.hypot(gx, gy) >= _EDGE_DN / 2.0) & (inside > 0)
    ys, xs = np.nonzero(edges)
    if len(xs) < _MIN_EDGE_PX:
        return None
    pad = _WINDOW_PX
    x0, y0 = max(int(xs.min()) - pad, 0), max(int(ys.min()) - pad, 0)
    x1 = min(int(xs.max()) + pad + 1, k.width_px)
    y1 = min(int(ys.max()) + pad + 1, k.height_px)
    roi_b = grey_b[y0:y1, x0:x1]
    corners = [(x0, y0), (x1 - 1, y0), (x1 - 1, y1 - 1), (x0, y1 - 1)]
    local = np.array([(u - x0, v - y0) for u, v in corners], np.float32)
    heights = [lo_m + i * step_m for i in range(math.floor((hi_m - lo_m) / step_m) + 1)]
    costs = np.full((len(heights), y1 - y0, x1 - x0), np.inf, np.float32)
    for i, h in enumerate(heights):
        try:
            world = [(*ground_point(u, v, pose_b, k, plane_z_m=h), h) for u, v in corners]
        except NavError:
            continue
        pix = project(np.array(world), pose_a, k)
        if not bool(np.all(pix[:, 2] > 0.0)):
            continue
        to_a = cv2.getPerspectiveTransform(local, pix[:, :2].astype(np.float32))
        warped = cv2.warpPerspective(
            grey_a,
            to_a,
            (x1 - x0, y1 - y0),
            flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
            borderMode=cv2.BORDER_CONSTANT,
            borderValue=-1000.0,
        )
        costs[i] = cv2.blur(np.abs(roi_b - warped), (_WINDOW_PX, _WINDOW_PX))
    curves = costs[:, ys - y0, xs - x0]  # (heights, edge pixels)
    finite = np.isfinite(curves).all(axis=0)
    if not finite.any():
        return None
    curves = curves[:, finite]
    best = curves.argmin(axis=0)
    best_cost = curves.min(axis=0)
    typical = np.median(curves, axis=0)
    agree = best_cost <= _UNIQUE * typical
    found = np.sort(np.asarray(heights)[best[agree]])[::-1]
    if len(found) < _MIN_EDGE_PX:
        return None
    return float(found[max(int(len(found) * _TOP_SHARE), _MIN_EDGE_PX) - 1])
