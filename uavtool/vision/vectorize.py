"""Vectorization (paper III-A): colour filtering, borders, evenly spaced points, RDP.

``vectorize(frame_rgb, params)`` is pure: the same frame and parameters give bit-identical
shapes on any machine. OpenCV does the integer work (HSV, masks, contour tracing) and is run
single-threaded; everything after the contour is IEEE float64 arithmetic in a fixed order.

Only the bounding box of the pixels that have a colour at all is classified and traced —
the rest of the frame cannot hold a shape — and the borders of all colours are simplified
together (:mod:`uavtool.vision.outline`).
"""

from __future__ import annotations

import dataclasses
from typing import Any, NamedTuple

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.vision.colour import brightest_shade, hue_distance_deg, hue_lut, hue_of
from uavtool.vision.errors import ImageError
from uavtool.vision.outline import (
    longest_stub,
    offset_ring,
    resample_ring,
    ring_detail,
    simplify_rings_detail,
)
from uavtool.vision.params import VectorizeParams
from uavtool.vision.roof import (
    INSET_PX,
    LEAST_SPREAD_DN,
    far_edge_pixels,
    roof_tolerance,
    roof_value,
)
from uavtool.vision.shapes import STAIRCASE_PX, FloatArray, Shape, orient

U8Array = npt.NDArray[np.uint8]
# What OpenCV returns (its stubs type every array loosely).
CvArray = npt.NDArray[Any]

# hue_of and hue_distance_deg live in uavtool.vision.colour; importable from here too.
__all__ = [
    "CvArray",
    "U8Array",
    "hue_distance_deg",
    "hue_of",
    "non_ground",
    "not_ground_regions",
    "vectorize",
]


def vectorize(
    frame_rgb: U8Array,
    params: VectorizeParams | None = None,
    *,
    nadir_px: tuple[float, float] | None = None,
) -> tuple[Shape, ...]:
    """The coloured regions of an RGB frame ``(h, w, 3) uint8`` as shapes.

    Shapes are ordered by palette colour, then by area (largest first). With ``roof_only``,
    each region keeps its roof's shade, told by geometry (:mod:`uavtool.vision.roof`):
    ``nadir_px`` is the photo's point straight below the camera, ``(u, v)``; by default the
    image centre (a camera looking straight down). Raises :class:`ImageError` for anything
    but an ``(h, w, 3)`` uint8 array.
    """
    p = params if params is not None else VectorizeParams()
    frame = _check_frame(frame_rgb)
    cv2.setNumThreads(1)
    hue, sat, val = cv2.split(cv2.cvtColor(frame, cv2.COLOR_RGB2HSV_FULL))
    valid = cv2.bitwise_and(
        cv2.threshold(sat, p.min_saturation - 1, 255, cv2.THRESH_BINARY)[1],
        cv2.threshold(val, p.min_value - 1, 255, cv2.THRESH_BINARY)[1],
    )
    x, y, w, h = cv2.boundingRect(valid)
    if w == 0:
        return ()
    # Work on the box around every pixel with a colour, grown by the median filter's
    # reach: outside it the class image is 0 before and after filtering.
    grow = max(p.denoise_px // 2, 1)
    x0, y0 = max(x - grow, 0), max(y - grow, 0)
    x1, y1 = min(x + w + grow, frame.shape[1]), min(y + h + grow, frame.shape[0])
    box = (slice(y0, y1), slice(x0, x1))
    hue, valid = hue[box], valid[box]
    lut = hue_lut(hue, valid, p)
    n_classes = int(lut.max())
    if n_classes == 0:
        return ()
    classes = cv2.bitwise_and(cv2.LUT(hue, lut), valid)
    if p.denoise_px > 1:
        # The median of class ids is always one of the ids present, so no class is invented.
        classes = cv2.medianBlur(classes, p.denoise_px)
    regions: list[_Region] = []
    for k in range(1, n_classes + 1):
        mask = cv2.inRange(classes, k, k)
        # Each colour is traced in its own bounding box (all of its pixels are inside).
        bx, by, bw, bh = cv2.boundingRect(mask)
        if bw == 0:
            continue
        sub = (slice(by, by + bh), slice(bx, bx + bw))
        mask = mask[sub]
        every = mask
        if p.roof_only:
            nadir = nadir_px if nadir_px is not None else _centre(frame)
            mask = _roofs(val, mask, (x0 + bx, y0 + by), frame.shape[:2], nadir, p)
        regions.extend(_regions(mask, every, (x0 + bx, y0 + by), frame.shape[:2], k, p))
    shapes = [
        (r.colour_class, -shape.area_px, order, shape)
        for order, r, shape in _traced(frame, regions, p)
    ]
    shapes.sort(key=lambda t: t[:3])
    return tuple(s for *_, s in shapes)


_PAD_PX = INSET_PX + 2
"""How far around a colour's box its roofs are looked for edges: past the reading inset."""


def _centre(frame: U8Array) -> tuple[float, float]:
    return ((frame.shape[1] - 1) / 2.0, (frame.shape[0] - 1) / 2.0)


def _roofs(
    val: CvArray,
    mask: CvArray,
    at: tuple[int, int],
    frame_hw: tuple[int, int],
    nadir: tuple[float, float],
    p: VectorizeParams,
) -> CvArray:
    """The part of ``mask`` (one colour, a box at frame pixel ``at``; ``val``: the frame's
    HSV V channel) that is roof: each region's pixels as near the shade its far edges show
    as those edges' own pixels are (`roof_tolerance`: the roof's noise, at most
    ``roof_value_tolerance``; :mod:`uavtool.vision.roof`). A region with less of a far
    edge in the picture than ``min_edge_px`` takes the shade (and spread) its colour's other
    regions show; a colour with too little anywhere keeps its brightest shade, as light
    from high above draws a roof."""
    bh, bw = mask.shape
    (fx, fy), (fh, fw) = at, frame_hw
    px0, py0 = max(fx - _PAD_PX, 0), max(fy - _PAD_PX, 0)
    px1, py1 = min(fx + bw + _PAD_PX, fw), min(fy + bh + _PAD_PX, fh)
    padded = np.zeros((py1 - py0, px1 - px0), np.uint8)
    padded[fy - py0 : fy - py0 + bh, fx - px0 : fx - px0 + bw] = mask
    value = val[py0:py1, px0:px1]
    votes = far_edge_pixels(padded, (nadir[0] - px0, nadir[1] - py0))
    tol = p.roof_value_tolerance
    # a roof edge is an edge: at least min_edge_px long, or it is the stub of a corner
    least = max(int(np.ceil(p.min_edge_px)), 1)
    shade = roof_value(value, votes, tol) if len(votes[0]) >= least else None
    if shade is None:
        return brightest_shade(value[fy - py0 : fy - py0 + bh, fx - px0 : fx - px0 + bw], mask, p)
    count, labels = cv2.connectedComponents(padded, connectivity=8)
    shades = np.full(count, shade, np.int16)
    spread = roof_tolerance(value, votes, shade, tol)
    tols = np.full(count, spread, np.int16)
    vs, us = votes
    owner = labels[vs, us]
    # (np.unique would import numpy.ma: tests/test_imports.py)
    for label in np.flatnonzero(np.bincount(owner, minlength=count) >= least).tolist():
        mine = owner == label
        own = roof_value(value, (vs[mine], us[mine]), tol)
        if own is not None:
            shades[label] = own
            tols[label] = roof_tolerance(value, (vs[mine], us[mine]), own, tol)
    near = np.abs(value.astype(np.int16) - shades[labels]) <= tols[labels]
    roof: CvArray = np.where(near & (padded > 0), 255, 0).astype(np.uint8)
    if p.denoise_px > 1 and int(tols.max()) > LEAST_SPREAD_DN:
        # in a noisy photo a wall lit just beyond the roof's spread has pixels within it:
        # specks, which the median drops as it drops them from the colour classes (a photo
        # without noise has none)
        roof = cv2.bitwise_and(cv2.medianBlur(roof, p.denoise_px), padded)
    return roof[fy - py0 : fy - py0 + bh, fx - px0 : fx - px0 + bw]


def _traced(
    frame: U8Array, regions: list[_Region], p: VectorizeParams
) -> list[tuple[int, _Region, Shape]]:
    """(order, region, shape with its inside colour) for each region whose outline keeps
    three corners once the outlines are simplified together."""
    contours = [c for r in regions for c in (r.outer, *r.holes)]
    rings, details, left_outs = simplify_rings_detail(contours, p)
    out: list[tuple[int, _Region, Shape]] = []
    at = 0
    for order, r in enumerate(regions):
        outer, holes = rings[at], rings[at + 1 : at + 1 + len(r.holes)]
        detail, left_out = details[at], left_outs[at]
        at += 1 + len(r.holes)
        if len(outer) < 3:
            continue
        shape = _offset_shape(outer, tuple(h for h in holes if len(h) >= 3), r.cut, detail, p)
        shape = dataclasses.replace(
            shape, colour_rgb=_inside_colour(frame, r, shape), left_out_px=left_out
        )
        if detail > STAIRCASE_PX:
            left_out = _left_out_with_walls(frame, r, outer, shape, p)
            detail = max(left_out, longest_stub(outer, p.min_edge_px))
            shape = dataclasses.replace(shape, detail_px=detail, left_out_px=left_out)
        out.append((order, r, shape))
    return out


def _left_out_with_walls(
    frame: U8Array, r: _Region, outer: FloatArray, shape: Shape, p: VectorizeParams
) -> float:
    """What ``shape``'s outline (``outer`` before its edge offset) leaves out of its region
    once the building's own walls inside the outline count as the building: the line of
    wall between two roofs of one building, which the roof's border runs into as a slit, is
    none of the footprint's detail; a step between its tiers, or a notch, is."""
    x, y, w, h = cv2.boundingRect(r.contour)
    box = (slice(y, y + h), slice(x, x + w))
    region: CvArray = np.zeros((h, w), np.uint8)
    cv2.drawContours(region, [r.contour], 0, 255, cv2.FILLED, offset=(-x, -y))
    inside: CvArray = np.zeros((h, w), np.uint8)
    cv2.fillPoly(inside, [_ring(shape.polygon_px - (x, y))], 255)
    walls = same_paint(frame[box], shape.colour_rgb) & (inside > 0)
    region[walls] = 255
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE, offset=(x, y))
    if not contours:
        return 0.0
    border = max(contours, key=cv2.contourArea)[:, 0, :].astype(np.float64)
    return ring_detail(resample_ring(border, p.point_spacing_px), outer)


def non_ground(
    frame_rgb: U8Array,
    params: VectorizeParams | None = None,
    *,
    tolerance_dn: int = 15,
    within: CvArray | None = None,
    nadir_px: tuple[float, float] | None = None,
) -> tuple[Shape, ...]:
    """The roofs of everything in an RGB frame that is not the ground, whatever its colour,
    largest first. Not ground: pixels differing from the ground's colour (the frame's most
    common colour, to 8 levels) by more than ``tolerance_dn`` in a channel; a roof: the part
    of such a region in the colour its edges facing away from the nadir show
    (:mod:`uavtool.vision.roof`; ``nadir_px`` by default the image centre), or, with too
    little of such an edge in the picture, in its brightest colour that covers a tenth of it
    (walls are shaded darker than roofs by light from high above).
    This is what the obstacle map is made of: grey, white or black roofs, and a darker shade
    of a colour, which :func:`vectorize` leaves out, are here. ``within`` (a mask of the
    frame's size, non-zero where to look) keeps only what lies in it.
    A region may join several things that touch in the photo (a building, the car park
    beside it, another building of the ground's hue beyond): once its roof and that roof's
    own paint (its walls) are taken out, what is left of another colour is looked at again,
    as regions of their own (up to `_PARTS_DEEP` times)."""
    p = params if params is not None else VectorizeParams()
    frame = _check_frame(frame_rgb)
    free = _not_ground_mask(frame, p, tolerance_dn)
    mask = free
    if within is not None:
        mask = cv2.bitwise_and(free, cv2.threshold(within, 0, 255, cv2.THRESH_BINARY)[1])
    nadir = nadir_px if nadir_px is not None else _centre(frame)
    return _non_ground_in(frame, free, mask, _colour_codes(frame), nadir, p, 0)


def _non_ground_in(
    frame: U8Array,
    free: CvArray,
    mask: CvArray,
    codes: npt.NDArray[np.int32],
    nadir: tuple[float, float],
    p: VectorizeParams,
    depth: int,
) -> tuple[Shape, ...]:
    """`non_ground`'s roofs of the regions of ``mask`` (part of ``free``, the frame's pixels
    that are not ground; ``codes``: the frame's `_colour_codes`), and, ``depth`` times
    looked at again so far, of what each region holds besides its roof and that roof's
    paint."""
    regions = _regions(mask, mask, (0, 0), frame.shape[:2], 1, p)
    least = max(int(np.ceil(p.min_edge_px)), 1)
    roofs: list[_Region] = []
    parts: list[Shape] = []
    for r in regions:
        inside = np.zeros_like(mask)
        cv2.drawContours(inside, [r.contour], 0, 255, cv2.FILLED)
        rgb = _roof_rgb(codes, inside, _far_edge(inside, r.contour, nadir), least)
        roof = cv2.bitwise_and(_near(frame, rgb, _ROOF_TOLERANCE_DN), inside)
        if p.denoise_px > 1:
            roof = cv2.medianBlur(roof, p.denoise_px)
        found = _regions(roof, roof, (0, 0), frame.shape[:2], 1, p)
        if found:
            roofs.append(max(found, key=lambda f: cv2.contourArea(f.contour)))
        if depth < _PARTS_DEEP:
            x, y, w, h = cv2.boundingRect(r.contour)
            # a region a line thin (a wall's edge seen end on) is looked at in a box of at
            # least 3 pixels each way: what `same_paint` takes
            x, y = min(x, frame.shape[1] - 3), min(y, frame.shape[0] - 3)
            box = (slice(y, y + max(h, 3)), slice(x, x + max(w, 3)))
            rest = inside.copy()  # zero outside the region's box
            rest[box][(roof[box] > 0) | same_paint(frame[box], rgb)] = 0
            if cv2.countNonZero(rest) >= p.min_area_px:
                more = cv2.bitwise_and(free, rest)
                parts.extend(_non_ground_in(frame, free, more, codes, nadir, p, depth + 1))
    shapes = [(-shape.area_px, order, shape) for order, _r, shape in _traced(frame, roofs, p)]
    shapes += [(-shape.area_px, len(shapes) + i, shape) for i, shape in enumerate(parts)]
    shapes.sort(key=lambda t: t[:2])
    return tuple(s for *_, s in shapes)


_PARTS_DEEP = 2
"""How many times what is left of a region, its roof and walls taken out, is looked at again
(`non_ground`): a building, the car park it touches and one more beyond."""


def not_ground_regions(
    frame_rgb: U8Array,
    params: VectorizeParams | None = None,
    *,
    tolerance_dn: int = 15,
    within: CvArray | None = None,
) -> tuple[Shape, ...]:
    """The outlines of the regions of an RGB frame that are not the ground (as
    :func:`non_ground` tells it), roofs and walls together, largest first: one building
    with everything seen of it, or several that touch in the photo. ``within``: only
    where that mask is non-zero (what else is known to lie on the ground left out)."""
    p = params if params is not None else VectorizeParams()
    frame = _check_frame(frame_rgb)
    mask = _not_ground_mask(frame, p, tolerance_dn)
    if within is not None:
        mask = cv2.bitwise_and(mask, within)
    regions = _regions(mask, mask, (0, 0), frame.shape[:2], 1, p)
    shapes = [(-shape.area_px, order, shape) for order, _r, shape in _traced(frame, regions, p)]
    shapes.sort(key=lambda t: t[:2])
    return tuple(s for *_, s in shapes)


def _not_ground_mask(frame: U8Array, p: VectorizeParams, tolerance_dn: int) -> CvArray:
    """255 where a pixel differs from the ground's colour, denoised."""
    cv2.setNumThreads(1)
    mask = cv2.bitwise_not(_near(frame, _mode_rgb(frame), tolerance_dn))
    if p.denoise_px > 1:
        mask = cv2.medianBlur(mask, p.denoise_px)
    return mask


def roof_inside(
    frame_rgb: U8Array, shape: Shape, *, inset_px: int, tolerance_dn: int = 15
) -> CvArray:
    """A mask of ``shape``'s roof proper: inside its outline, not in its holes, and at least
    ``inset_px`` from its outline and from any pixel of the ground's colour (a courtyard or
    an opening shows the ground; a wall between two tiers of one building does not)."""
    frame = _check_frame(frame_rgb)
    inside = outline_mask(frame, shape)
    inside = cv2.bitwise_and(inside, cv2.bitwise_not(ground_mask(frame, tolerance_dn=tolerance_dn)))
    side = 2 * inset_px + 1
    return cv2.erode(inside, np.ones((side, side), np.uint8))


def outline_mask(frame: U8Array, shape: Shape) -> CvArray:
    """255 inside ``shape``'s outline and not in its holes, over ``frame``'s pixels."""
    inside: CvArray = np.zeros(frame.shape[:2], np.uint8)
    cv2.fillPoly(inside, [_ring(shape.polygon_px)], 255)
    for hole in shape.holes_px:
        cv2.fillPoly(inside, [_ring(hole)], 0)
    return inside


def ground_mask(frame_rgb: U8Array, *, tolerance_dn: int = 15) -> CvArray:
    """255 where a pixel has the ground's colour (the frame's most common, to 8 levels)."""
    frame = _check_frame(frame_rgb)
    return _near(frame, _mode_rgb(frame[::4, ::4]), tolerance_dn)  # every 16th pixel will do


def inner_walls(
    frame_rgb: U8Array,
    shape: Shape,
    *,
    tolerance_dn: int = 15,
    least_px: int = 3,
    nadir_px: tuple[float, float] | None = None,
    shade_dn: int | None = None,
) -> list[npt.NDArray[np.int32]]:
    """The walls seen inside ``shape``'s roof: strips of another shade of its colour (the
    same hue; grey for a grey roof; in some channel more than ``shade_dn`` from the roof's,
    by default twice ``tolerance_dn``) that do not stand on the ground. Seen from above, a
    roof's own walls lie outside its outline, and a courtyard's go down to the ground that
    shows between them: a wall inside the outline that stands on this roof is under a higher
    part of the building. Each strip is its ``(n, 2)`` pixels ``(u, v)``, at least
    ``least_px`` of them.

    Without ``nadir_px`` a strip that comes within two pixels of the ground is dropped. With
    it (the photo's point straight below the camera), only a strip whose foot is on the
    ground is: a wall's foot is its side toward the nadir, and a courtyard's wall has the
    courtyard's floor there, while a higher tier's wall, whose ends may reach the lower
    tier's edge, has the lower roof at its foot."""
    frame = _check_frame(frame_rgb)
    inside = roof_inside(frame, shape, inset_px=1, tolerance_dn=tolerance_dn)
    # a channel more than ``shade`` from the roof's: inRange's exact integer test is
    # ~30x faster than numpy's per-pixel max over three channels
    shade = 2 * tolerance_dn if shade_dn is None else shade_dn
    other = (
        cv2.bitwise_not(_near(frame, shape.colour_rgb, shade))
        if shade >= 0
        else np.ones(frame.shape[:2], np.uint8)
    )
    strips = (inside > 0) & (other > 0) & same_paint(frame, shape.colour_rgb)
    ground = ground_mask(frame, tolerance_dn=tolerance_dn)
    near_ground = cv2.dilate(ground, np.ones((5, 5), np.uint8)) > 0
    count, labels = cv2.connectedComponents(strips.astype(np.uint8), connectivity=8)
    out: list[npt.NDArray[np.int32]] = []
    for label in range(1, count):
        strip = labels == label
        vs, us = np.nonzero(strip)
        if len(us) < least_px:
            continue
        if near_ground[vs, us].any() and (
            nadir_px is None or _foot_on_ground(us, vs, strip, ground, nadir_px)
        ):
            continue
        out.append(np.stack([us, vs], axis=1).astype(np.int32))
    return out


_FOOT_PX = 2.0
"""How far toward the nadir from a wall's pixel its foot is looked for: past the blended
pixel at the wall's edge."""


def _foot_on_ground(
    us: npt.NDArray[np.intp],
    vs: npt.NDArray[np.intp],
    strip: npt.NDArray[np.bool_],
    ground: CvArray,
    nadir_px: tuple[float, float],
) -> bool:
    """Whether at least half of what lies beside the strip on its nadir side is ground."""
    du, dv = nadir_px[0] - us, nadir_px[1] - vs
    rho = np.hypot(du, dv)
    away = rho >= _FOOT_PX  # a pixel under the camera shows no foot
    if not away.any():
        return True
    step = _FOOT_PX / rho[away]
    fu = np.round(us[away] + du[away] * step).astype(np.int64)
    fv = np.round(vs[away] + dv[away] * step).astype(np.int64)
    h, w = strip.shape
    seen = (fu >= 0) & (fu < w) & (fv >= 0) & (fv < h)
    fu, fv = fu[seen], fv[seen]
    foot = ~strip[fv, fu]  # the strip's own pixels are no foot
    if not foot.any():
        return True
    return float((ground[fv[foot], fu[foot]] > 0).mean()) >= 0.5


def enclosed_openings(
    frame_rgb: U8Array, shape: Shape, *, least_px: float, tolerance_dn: int = 15
) -> int:
    """How many regions inside ``shape``'s outline, besides its holes, show no roof: at
    least ``least_px`` pixels of another colour than the roof's, with roof all round them.

    From above, the roof fills its outline, and its own walls and the ground lie outside.
    What is enclosed is a courtyard too narrow or deep for its floor to show (its walls, a
    sliver of ground: the vectorizer then keeps no hole) or a higher part's walls. Two
    buildings that match one outline equally well may differ by it."""
    frame = _check_frame(frame_rgb)
    kernel = np.ones((3, 3), np.uint8)
    # the outline's blended edge pixels are no opening
    inside = cv2.erode(outline_mask(frame, shape), kernel)
    rim = cv2.subtract(inside, cv2.erode(inside, kernel))
    roof = _near(frame, shape.colour_rgb, 2 * tolerance_dn)
    other = cv2.bitwise_and(inside, cv2.bitwise_not(roof))
    count, labels, stats, _ = cv2.connectedComponentsWithStats(other, connectivity=8)
    touching = set(labels[rim > 0].tolist())
    return sum(
        1
        for label in range(1, count)
        if label not in touching and stats[label, cv2.CC_STAT_AREA] >= least_px
    )


def same_paint(frame_rgb: U8Array, colour_rgb: tuple[int, int, int]) -> npt.NDArray[np.bool_]:
    """Where ``frame_rgb`` shows ``colour_rgb``'s paint in any shade: its hue (within
    `_WALL_HUE_HALF_DEG`) and its saturation (within what `_SHADE_NOISE_DN` of noise in each
    channel makes of it at the pixel's brightness), or grey for a grey. A wall is its roof's
    colour shaded: one factor on every channel, which keeps both."""
    frame = _check_frame(frame_rgb)
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)
    own = cv2.cvtColor(np.array([[colour_rgb]], np.uint8), cv2.COLOR_RGB2HSV)[0, 0]
    if is_grey(colour_rgb):
        grey: npt.NDArray[np.bool_] = hsv[:, :, 1] < _GREY_SATURATION
        return grey
    # Per-pixel tests as look-up tables over the 256 values of one channel: the same
    # arithmetic, done once per value instead of once per pixel.
    hue, saturation, value = cv2.split(hsv)
    d = np.abs(_CHANNEL - int(own[0]))
    hue_lut = ((np.minimum(d, 180 - d) <= _WALL_HUE_HALF_DEG) * 255).astype(np.uint8)
    # S = (max - min) / max moves by at most 3 n / V for n of noise in each channel
    spread = (3 * 255 * _SHADE_NOISE_DN) // np.maximum(_CHANNEL, 1)
    least = np.clip(np.maximum(int(own[1]) - spread, _GREY_SATURATION), 0, 255).astype(np.uint8)
    most = np.clip(int(own[1]) + spread, 0, 255).astype(np.uint8)
    alike: npt.NDArray[np.bool_] = (
        (cv2.LUT(hue, hue_lut) > 0)
        & (saturation >= cv2.LUT(value, least))
        & (saturation <= cv2.LUT(value, most))
    )
    return alike


def is_grey(colour_rgb: tuple[int, int, int]) -> bool:
    """Whether ``colour_rgb`` is a grey: its paint (`same_paint`) is every unpainted
    surface's, whatever its shade."""
    own = cv2.cvtColor(np.array([[colour_rgb]], np.uint8), cv2.COLOR_RGB2HSV)[0, 0]
    return int(own[1]) < _GREY_SATURATION


def near_colour(frame_rgb: U8Array, rgb: tuple[int, int, int], tolerance_dn: int) -> CvArray:
    """255 where every channel of ``frame_rgb`` is within ``tolerance_dn`` of ``rgb``."""
    return _near(_check_frame(frame_rgb), rgb, tolerance_dn)


_CHANNEL = np.arange(256, dtype=np.int64)
"""Every value an 8-bit channel takes: the index of a look-up table."""
_GREY_SATURATION = 40
"""OpenCV saturation (0-255) under which a colour counts as grey (its hue says nothing)."""
_WALL_HUE_HALF_DEG = 8
"""How far (OpenCV hue units, 2° each) a wall's hue may lie from its roof's: a wall is the
roof's colour, shaded."""
_SHADE_NOISE_DN = 15
"""How far a shade's channels may lie from its paint's, shaded exactly (`ground_mask`'s
tolerance): rounding, sensor noise and texture."""


def _ring(points: FloatArray) -> CvArray:
    return np.round(np.asarray(points)).astype(np.int32).reshape(-1, 1, 2)


def _near(frame: U8Array, rgb: tuple[int, int, int], tolerance_dn: int) -> CvArray:
    lo = np.array([max(c - tolerance_dn, 0) for c in rgb], np.uint8)
    hi = np.array([min(c + tolerance_dn, 255) for c in rgb], np.uint8)
    return cv2.inRange(frame, lo, hi)


_ROOF_SHARE = 0.1
"""The least share of a region's pixels a colour must hold to be its roof's."""
_ROOF_TOLERANCE_DN = 6
"""How far (per channel) a roof's pixels may be from its colour: flat shading and noise."""


def _far_edge(
    inside: CvArray, contour: CvArray, nadir: tuple[float, float]
) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """:func:`far_edge_pixels` of a frame-sized mask, worked out around ``contour`` only."""
    x, y, w, h = cv2.boundingRect(contour)
    fh, fw = inside.shape
    x0, y0 = max(x - _PAD_PX, 0), max(y - _PAD_PX, 0)
    x1, y1 = min(x + w + _PAD_PX, fw), min(y + h + _PAD_PX, fh)
    vs, us = far_edge_pixels(inside[y0:y1, x0:x1], (nadir[0] - x0, nadir[1] - y0))
    return vs + y0, us + x0


def _roof_rgb(
    codes: npt.NDArray[np.int32],
    mask: CvArray,
    far_edge: tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]],
    least: int,
) -> tuple[int, int, int]:
    """The colour (to 8 levels; ``codes``: the frame's `_colour_codes`) most of the
    ``far_edge`` pixels show, when there are at least ``least`` of them; else the brightest
    colour holding at least `_ROOF_SHARE` of the pixels under ``mask``: light from high
    above lights a roof better than the walls around it."""
    if len(far_edge[0]) >= least:
        edge_codes = codes[far_edge]
        return _code_rgb(int(np.argmax(np.bincount(edge_codes, minlength=1 << 15))))
    under = codes[mask != 0]
    counts = np.bincount(under, minlength=1 << 15)
    common = np.flatnonzero(counts >= _ROOF_SHARE * len(under))
    if len(common) == 0:
        common = np.array([int(np.argmax(counts))])
    brightness = (common >> 10) + ((common >> 5) & 31) + (common & 31)
    return _code_rgb(int(common[int(np.argmax(brightness))]))


def _mode_rgb(frame: U8Array) -> tuple[int, int, int]:
    """The frame's most common colour, to 8 levels."""
    return _code_rgb(int(np.argmax(np.bincount(_colour_codes(frame).ravel(), minlength=1 << 15))))


def _colour_codes(frame: U8Array) -> npt.NDArray[np.int32]:
    """Each pixel's colour, every channel quantized to 8 levels, as one 15-bit code."""
    q = (frame >> 3).astype(np.int32)
    codes: npt.NDArray[np.int32] = (q[:, :, 0] << 10) | (q[:, :, 1] << 5) | q[:, :, 2]
    return codes


def _code_rgb(code: int) -> tuple[int, int, int]:
    """The colour at the centre of a code's bin."""
    return ((code >> 10) * 8 + 4, ((code >> 5) & 31) * 8 + 4, (code & 31) * 8 + 4)


def _check_frame(frame_rgb: U8Array) -> U8Array:
    arr = np.asarray(frame_rgb)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.dtype != np.uint8:
        raise ImageError(f"expected an (h, w, 3) uint8 RGB image, got {arr.shape} {arr.dtype}")
    if arr.shape[0] < 3 or arr.shape[1] < 3:
        raise ImageError(f"image too small: {arr.shape[1]}x{arr.shape[0]}")
    return np.ascontiguousarray(arr)


class _Region(NamedTuple):
    """One traced region: its border and hole borders (frame pixels), before simplifying."""

    colour_class: int
    contour: CvArray  # (n, 1, 2) int32, as OpenCV traced it
    outer: CvArray  # (n, 2)
    holes: tuple[CvArray, ...]
    cut: bool
    mask: CvArray  # the colour's mask over the working box
    origin: tuple[int, int]  # the box's top-left corner in the frame


def _regions(
    mask: CvArray,
    colour: CvArray,
    origin: tuple[int, int],
    frame_hw: tuple[int, int],
    k: int,
    p: VectorizeParams,
) -> list[_Region]:
    """The regions of a colour mask large enough to keep, with their holes. ``colour`` is
    every pixel of the colour, ``mask`` those that count (with ``roof_only``, the roofs): a
    hole must show at least ``min_hole_area_px`` pixels of something else. A hole in a roof
    that shows only the building's own walls (a higher block's, seen in perspective) is
    filled; a courtyard or a tunnel shows the ground."""
    contours, hierarchy = cv2.findContours(
        mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE, offset=origin
    )
    if len(contours) == 0:
        return []
    h, w = frame_hw
    tree = hierarchy[0].tolist()
    out: list[_Region] = []
    for i, contour in enumerate(contours):
        if tree[i][3] != -1:
            continue  # a hole; handled with its parent
        if cv2.contourArea(contour) + 0.5 * len(contour) < p.min_area_px:
            continue
        bx, by, bw, bh = cv2.boundingRect(contour)
        cut = bx == 0 or by == 0 or bx + bw == w or by + bh == h
        holes: list[CvArray] = []
        child = tree[i][2]
        while child != -1:
            hole = contours[child]
            if cv2.contourArea(hole) - 0.5 * len(hole) >= p.min_hole_area_px and (
                colour is mask or _shows_other(hole, colour, origin, p.min_hole_area_px)
            ):
                holes.append(hole[:, 0, :])
            child = tree[child][0]
        out.append(_Region(k, contour, contour[:, 0, :], tuple(holes), cut, mask, origin))
    return out


def _shows_other(hole: CvArray, colour: CvArray, origin: tuple[int, int], least: float) -> bool:
    """Whether at least ``least`` pixels inside ``hole`` (frame pixels) are not ``colour``'s
    (a mask over the box at ``origin``)."""
    x, y, w, h = cv2.boundingRect(hole)
    inside = np.zeros((h, w), np.uint8)
    cv2.drawContours(inside, [hole], 0, 255, cv2.FILLED, offset=(-x, -y))
    bx, by = x - origin[0], y - origin[1]
    other = cv2.bitwise_and(inside, cv2.bitwise_not(colour[by : by + h, bx : bx + w]))
    return cv2.countNonZero(other) >= least


def _offset_shape(
    outer: FloatArray, holes: tuple[FloatArray, ...], cut: bool, detail: float, p: VectorizeParams
) -> Shape:
    outer = orient(outer, positive=True)
    holes = tuple(orient(h, positive=False) for h in holes)
    return Shape.from_rings(
        colour_rgb=(0, 0, 0),
        polygon_px=offset_ring(outer, p.edge_offset_px),
        holes_px=tuple(offset_ring(h, p.edge_offset_px) for h in holes),
        cut_by_border=cut,
        detail_px=detail,
    )


def _inside_colour(frame: U8Array, region: _Region, shape: Shape) -> tuple[int, int, int]:
    """Median RGB of the region's pixels in the 3×3 window around a pixel inside it."""
    h, w = frame.shape[:2]
    mask, (x0, y0) = region.mask, region.origin
    mh, mw = mask.shape
    u, v = round(shape.centroid_px[0]), round(shape.centroid_px[1])
    inside = (
        0 <= u - x0 < mw
        and 0 <= v - y0 < mh
        and mask[v - y0, u - x0] != 0
        and cv2.pointPolygonTest(region.contour, (float(u), float(v)), False) > 0
    )
    if not inside:
        u, v = _deepest_pixel(mask, region.contour, region.origin)
    # The 3×3 window, clipped to the frame and to the box (the mask is 0 outside it).
    v0, v1 = max(v - 1, 0, y0), min(v + 2, h, y0 + mh)
    u0, u1 = max(u - 1, 0, x0), min(u + 2, w, x0 + mw)
    window = frame[v0:v1, u0:u1][mask[v0 - y0 : v1 - y0, u0 - x0 : u1 - x0] != 0]
    if len(window) == 0:
        window = frame[v : v + 1, u]
    med = np.sort(window, axis=0)[(len(window) - 1) // 2]
    return (int(med[0]), int(med[1]), int(med[2]))


def _deepest_pixel(mask: CvArray, contour: CvArray, origin: tuple[int, int]) -> tuple[int, int]:
    """The pixel of the contour's region farthest from its border (frame coordinates;
    ``mask`` covers the box whose top-left corner is ``origin``)."""
    x, y, bw, bh = cv2.boundingRect(contour)
    region = np.zeros((bh + 2, bw + 2), dtype=np.uint8)
    cv2.drawContours(region, [contour], 0, 255, thickness=cv2.FILLED, offset=(1 - x, 1 - y))
    mx, my = x - origin[0], y - origin[1]
    inside = cv2.bitwise_and(
        region,
        cv2.copyMakeBorder(
            mask[my : my + bh, mx : mx + bw], 1, 1, 1, 1, cv2.BORDER_CONSTANT, value=0
        ),
    )
    dist = cv2.distanceTransform(inside, cv2.DIST_L2, 3)
    k = int(np.argmax(dist))
    return (k % (bw + 2) + x - 1, k // (bw + 2) + y - 1)
