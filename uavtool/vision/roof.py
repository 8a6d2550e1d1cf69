"""Which face of a region seen from above is its roof: by geometry, not by brightness.

Seen from a camera above, a point higher up is drawn farther from the nadir (the photo's
point straight below the camera). A building's roof is therefore drawn displaced away from
the nadir over its walls, and every edge of its outline that faces away from the nadir is
the top of a wall: a roof's edge. The walls perspective shows lie on the nadir side of the
roof, between the roof and their foot. So whatever the light — a low sun can make a wall
brighter than the roof it stands under — the pixels just inside the outline's far side are
roof, and their shade is the roof's.

Everything here is integer pixel work and float64 arithmetic in a fixed order: the same
mask gives the same pixels on every machine.
"""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

CvArray = npt.NDArray[Any]

FACING_COS = 0.7
"""An outline edge faces away from the nadir when its outward normal lies within ~45° of
the direction away from it: the walls' own sides, drawn along rays from the nadir, are not
roof edges."""
INSET_PX = 2
"""How far inside the outline a roof edge's pixel is read: past the blended edge pixel."""


def far_edge_pixels(
    mask: CvArray, nadir_uv: tuple[float, float], inside: CvArray | None = None
) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """``(vs, us)`` of the pixels of ``mask`` (uint8, non-zero in the region) ``INSET_PX``
    inside the outline's edges that face away from ``nadir_uv`` (``(u, v)`` in ``mask``'s
    pixels, may lie outside it): from above, pixels of the region's roof. An edge on the
    border of ``inside`` (non-zero where the picture is; default: all of ``mask``) is
    where the picture ends, not the region: it is not read."""
    region = (mask > 0).astype(np.uint8)
    h, w = region.shape
    edge = cv2.subtract(region, cv2.erode(region, np.ones((3, 3), np.uint8)))
    vs, us = np.nonzero(edge)
    if len(vs) == 0:
        return vs, us
    # the outward normal: down the gradient of the region smoothed over 5 x 5 pixels (a
    # staircase of pixels is a straight edge), by central differences at its edge only
    smooth = cv2.copyMakeBorder(
        cv2.blur(region * np.uint8(25), (5, 5), borderType=cv2.BORDER_CONSTANT),
        1, 1, 1, 1, cv2.BORDER_CONSTANT, value=0,
    ).astype(np.int32)  # fmt: skip
    gu = (smooth[vs + 1, us + 2] - smooth[vs + 1, us]).astype(np.float64)
    gv = (smooth[vs + 2, us + 1] - smooth[vs, us + 1]).astype(np.float64)
    norm = np.hypot(gu, gv)
    du, dv = us - nadir_uv[0], vs - nadir_uv[1]
    rho = np.hypot(du, dv)
    ok = (norm > 1e-6) & (rho > 1e-6)
    nu, nv = -gu[ok] / norm[ok], -gv[ok] / norm[ok]
    vs, us = vs[ok], us[ok]
    facing = nu * du[ok] / rho[ok] + nv * dv[ok] / rho[ok] >= FACING_COS
    vs, us, nu, nv = vs[facing], us[facing], nu[facing], nv[facing]
    # the outline's edge must be the region's, not the picture's
    ou = np.round(us + INSET_PX * nu).astype(np.intp)
    ov = np.round(vs + INSET_PX * nv).astype(np.intp)
    seen = (ou >= 0) & (ou < w) & (ov >= 0) & (ov < h)
    if inside is not None:
        seen[seen] = inside[ov[seen], ou[seen]] > 0
    iu = np.round(us + -INSET_PX * nu).astype(np.intp)
    iv = np.round(vs + -INSET_PX * nv).astype(np.intp)
    seen &= (iu >= 0) & (iu < w) & (iv >= 0) & (iv < h)
    iu, iv = iu[seen], iv[seen]
    keep = region[iv, iu] > 0
    return iv[keep], iu[keep]


def roof_value(
    value: CvArray, votes: tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]], tolerance: int
) -> int | None:
    """The shade (a ``value`` channel 0–255) most of the roof-edge pixels ``votes`` share,
    to within half of ``tolerance``: the median of those; None without votes."""
    vs, us = votes
    if len(vs) == 0:
        return None
    shades = value[vs, us].astype(np.intp)
    hist = np.bincount(shades, minlength=256).astype(np.float64)
    half = max(tolerance // 2, 0)
    window = np.convolve(hist, np.ones(2 * half + 1), mode="same")
    # the busiest window, and the middle of the shades in it
    centre = int(np.argmax(window))
    inside = np.sort(shades[np.abs(shades - centre) <= half])
    return int(inside[(len(inside) - 1) // 2])


NOISE_SIGMAS = 5.0
"""How many of the roof's own standard deviations (from its edge pixels' median absolute
deviation) a pixel's shade may lie from the roof's and still be roof: noise that is
Gaussian, or bounded as the renderer's is, leaves no roof pixel further out."""
LEAST_SPREAD_DN = 3
"""What counts as roof beyond the roof's own spread, DN: a flat roof in a noise-free photo
is one shade, give or take the rounding of its colour and the camera's."""


def roof_tolerance(
    value: CvArray,
    votes: tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]],
    shade: int,
    limit: int,
) -> int:
    """How far (DN) a shade may lie from the roof's ``shade`` and be the roof's: the spread
    its edge pixels ``votes`` show around it (`NOISE_SIGMAS` robust standard deviations,
    plus `LEAST_SPREAD_DN`), never beyond ``limit``. A wall is another face, lit otherwise:
    one that differs from the roof by more than the roof's own noise is a wall, however
    close in shade — at a fixed ``limit`` of 20 DN a wall lit 5 DN off its roof was drawn
    with it, and the outline lay a wall's width outside the roof's edge."""
    vs, us = votes
    off = np.abs(value[vs, us].astype(np.int16) - shade)
    near = np.sort(off[off <= limit // 2])
    if near.size == 0:
        return limit
    mad = float(near[(near.size - 1) // 2])  # the median (np.median imports numpy.ma)
    return min(limit, math.ceil(NOISE_SIGMAS * 1.4826 * mad) + LEAST_SPREAD_DN)
