"""Whether what a photo from above shows lies on the ground, by parallax between two photos.

Two photos from above taken from different places (the mission's two overviews: one above
the other) draw the ground, and any flat surface, in two places related by the plane's
homography; a surface at another height moves by another. So a region of one colour is on
the ground when the other photo, carried over as the ground would be, puts that colour
where this photo shows it better than carried as any height the photos can tell from the
ground. Its colour, its size and how common it is in the frame say nothing of that: a lawn,
a road or a whole field of grass is ground, a green roof is not.

Near the point below the cameras no height moves anything (the photos are taken along one
vertical): there, and wherever the other photo does not reach, the answer is "not known".
"""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.nav.errors import NavError
from uavtool.nav.projection import frame_corners_px, frame_on_plane

CvArray = npt.NDArray[Any]

PARALLAX_PX = 2.0
"""The least shift between two planes' drawings of a region, in pixels, that tells them
apart: each photo draws an edge to within a pixel (the vectorizer's outline accuracy)."""
HEIGHTS_M = (1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 17.0, 23.0, 30.0, 38.0)
"""The heights above the ground the sweep tries: a roof at any height between two of them
is carried nearer to one of them than to the ground."""
STOREY_M = 3.0
"""The lowest a building stands: one storey. A region the photos can tell from a plane this
high (or lower) only is on the ground if it fits the ground best; where they cannot tell
even that, it may be a building."""
GRAIN_RATIO = 0.5
"""How much less a textured surface's pixels must differ lined up than misaligned, at the
median, for its grain to tell its height. Lined up, two photos differ by their noise n;
misaligned, by the grain g as well: sqrt(n² + g²). Half: a grain of at least sqrt(3) n."""
_NEAR_DN = 30
"""How far (per channel) the other photo's pixel may be from the region's colour: flat
shading is one colour per face, and a ground texture or sensor noise a few levels."""


def plane_homography(
    pose_from: CameraPose, pose_to: CameraPose, intrinsics: Intrinsics, plane_z_m: float
) -> npt.NDArray[np.float64]:
    """The 3x3 map from pixels of a photo taken at ``pose_from`` to pixels of one taken at
    ``pose_to`` (same camera) for points on the plane z = ``plane_z_m``. NavError when a
    frame's corner does not meet the plane (the camera looks above it)."""
    corners = np.array(frame_corners_px(intrinsics), np.float32)
    world = frame_on_plane(pose_from, intrinsics, plane_z_m=plane_z_m)
    there = project(np.array([(x, y, plane_z_m) for x, y in world]), pose_to, intrinsics)
    return cv2.getPerspectiveTransform(corners, there[:, :2].astype(np.float32)).astype(np.float64)


def on_ground(
    region: CvArray,
    colour_rgb: tuple[int, int, int],
    image: npt.NDArray[np.uint8],
    pose: CameraPose,
    other: npt.NDArray[np.uint8],
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    top_m: float,
    least_px: float,
    hidden: CvArray | None = None,
) -> bool | None:
    """Whether ``region`` (uint8 mask over ``image``, a photo from above at ``pose``) of
    colour ``colour_rgb`` lies on the ground: True when ``other`` (a photo from above at
    ``other_pose``), carried into ``image`` as the ground, shows that colour where ``image``
    does better than carried as any height up to ``top_m`` it can tell from the ground;
    False when some height does better; None when the photos cannot tell: the region is
    near the point below the cameras, ``other`` shows less than ``least_px`` pixels of it
    carried as the ground or as any of those heights, or the photos tell it only from what
    stands higher than a storey (`STOREY_M`). ``hidden`` (uint8 mask over ``other``): where
    ``other`` shows what hides the ground (buildings known to stand there), left out."""
    least = least_telling_m(region, pose, other_pose, intrinsics, top_m)
    if least is None or least > STOREY_M:
        return None
    # the region's box: where its pixels are
    x0, y0, bw, bh = cv2.boundingRect(region)
    x1, y1 = x0 + bw, y0 + bh
    box = (slice(y0, y1), slice(x0, x1))
    here = image[box]
    mine = cv2.bitwise_and(_near(here, colour_rgb), region[box])
    ones = _showing(other, hidden)
    size = (x1 - x0, y1 - y0)

    def misfit(z: float) -> tuple[float, float] | None:
        """How far the other photo carried as the plane z is from this one over the
        region's pixels (of those it shows at all), on average and at the median: a flat
        surface's edges, and the grain of a textured ground, line up only at their own
        height."""
        try:
            hom = plane_homography(other_pose, pose, intrinsics, z)
        except NavError:
            return None
        carried, inside = _carry(other, ones, hom, (x0, y0), size)
        seen = cv2.bitwise_and(mine, inside)
        shown = cv2.countNonZero(seen)
        if shown < least_px:
            return None  # the other photo shows too little of it
        differ = cv2.absdiff(here, carried).astype(np.float64).sum(axis=2)[seen > 0]
        return float(differ.sum()) / shown, _median(differ)

    ground = misfit(0.0)
    if ground is None:
        return None
    # every height it may stand at must be tried: one the other photo cannot show it at
    # (carried out of its frame) might be the one that fits
    heights = [z for z in HEIGHTS_M if least <= z <= top_m]
    fits = [misfit(z) for z in heights]
    if not fits or any(f is None for f in fits):
        return None
    tried = [(z, f) for z, f in zip(heights, fits, strict=True) if f is not None]
    # Below the least telling height a plane moves the region by less than the photos can
    # be sure of, so it cannot tell the region off the ground; but one that fits better
    # than the ground does says the region is no better drawn lying on it (a low roof
    # whose edges are few: a strip of a larger roof of its colour).
    if ground[0] < min(f[0] for _, f in tried) and all(
        f is None or ground[0] <= f[0] for f in (misfit(z) for z in HEIGHTS_M if z < least)
    ):
        return True
    # A region as wide as the frame has little edge, and what stands on it (buildings,
    # each drawn at its own height) weighs on the average: its grain tells, at the median,
    # when lined up it differs less than half as much as carried as any building's height
    # (a storey and up) would misalign it: a grain standing out of the noise.
    storeys = [f[1] for z, f in tried if z >= STOREY_M]
    return bool(storeys) and ground[1] < GRAIN_RATIO * min(storeys)


def stands_out(
    region: CvArray,
    colour_rgb: tuple[int, int, int],
    image: npt.NDArray[np.uint8],
    pose: CameraPose,
    other: npt.NDArray[np.uint8],
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    least_px: float,
    hidden: CvArray | None = None,
) -> bool:
    """Whether a patch of at least ``least_px`` pixels of ``region`` (uint8 mask over
    ``image``, a photo from above at ``pose``) of colour ``colour_rgb``, where ``other`` (a
    photo from above at ``other_pose``) shows it, is drawn otherwise in ``other`` carried as
    the ground (a channel off by more than the colour's tolerance), once slivers a pixel
    wide along its edges are opened away. :func:`on_ground` weighs a region as a whole: a
    tower of a road's grey, joined to the road in the photo, is a few of its pixels, and
    the road lines up. Its patch, drawn elsewhere in the other photo (or hidden there),
    stands out; so does ground hidden behind a building, which is no evidence either way:
    ``hidden`` (uint8 mask over ``other``) is where ``other`` shows what hides the ground
    (buildings known to stand there), left out."""
    x0, y0, bw, bh = cv2.boundingRect(region)
    if bw == 0 or bh == 0:
        return False
    try:
        hom = plane_homography(other_pose, pose, intrinsics, 0.0)
    except NavError:
        return True  # the ground is not drawn: nothing is told
    box = (slice(y0, y0 + bh), slice(x0, x0 + bw))
    here = image[box]
    mine = cv2.bitwise_and(_near(here, colour_rgb), region[box])
    carried, inside = _carry(other, _showing(other, hidden), hom, (x0, y0), (bw, bh))
    off = (cv2.absdiff(here, carried).max(axis=2) > _NEAR_DN) & (mine > 0) & (inside > 0)
    patch = cv2.morphologyEx(off.astype(np.uint8) * 255, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    _, _, stats, _ = cv2.connectedComponentsWithStats(patch, connectivity=8)
    return bool((stats[1:, cv2.CC_STAT_AREA] >= least_px).any())


def roof_by_alignment(
    region: CvArray,
    colour_rgb: tuple[int, int, int],
    image: npt.NDArray[np.uint8],
    pose: CameraPose,
    other: npt.NDArray[np.uint8],
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    top_m: float,
    least_px: float,
) -> float | None:
    """The highest the flat roof ``region`` (uint8 mask over ``image``, a photo from above at
    ``pose``) of colour ``colour_rgb`` shows may stand (0 to ``top_m``), by the planes that
    carry ``other`` (a photo from above at ``other_pose``) onto it: for a roof drawn too
    small for its outline's corners and centroid to be placed to a pixel, every pixel of
    it, and the edge around it, line up only at its own height.

    A plane's misfit: how far the carried pixels differ from the region's. The planes are
    swept from the ground up, a quarter of a pixel's shift apart, as far as ``other``
    shows the region whole. A larger roof of the colour in ``other`` lines up with the
    region too, at its own height: the caller sweeps both ways. The answer is the highest
    plane whose misfit is within 1 / `GRAIN_RATIO` of the best's, or drawn within half
    `PARALLAX_PX` of it; a wall of the roof's shade beside it lines up almost as well a
    little lower, so the answer errs high, on the safe side. None when no plane ``other``
    shows above the answer is told from it (drawn `PARALLAX_PX` or more away): what stands
    higher is not ruled out."""
    x0, y0, bw, bh = cv2.boundingRect(region)
    if bw == 0 or bh == 0:
        return None
    # the region's box and a border: what lies beside it is what a wrong plane carries in
    pad = math.ceil(2 * PARALLAX_PX)
    x1, y1 = min(x0 + bw + pad, image.shape[1]), min(y0 + bh + pad, image.shape[0])
    x0, y0 = max(x0 - pad, 0), max(y0 - pad, 0)
    here = image[y0:y1, x0:x1]
    mine = cv2.bitwise_and(_near(here, colour_rgb), region[y0:y1, x0:x1])
    count = cv2.countNonZero(mine)
    if count < least_px:
        return None
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    pts = np.concatenate([c[:, 0, :] for c in contours]).astype(np.float64).reshape(-1, 1, 2)
    ones = _showing(other, None)
    size = (x1 - x0, y1 - y0)
    try:
        back = cv2.perspectiveTransform(
            pts, np.linalg.inv(plane_homography(other_pose, pose, intrinsics, 0.0))
        )
    except (NavError, np.linalg.LinAlgError):
        return None
    heights: list[float] = []
    drawn: list[npt.NDArray[np.float64]] = []  # the outline's pixels as each plane draws them
    fits: list[float] = []
    z = 0.0
    while True:
        try:
            hom = plane_homography(other_pose, pose, intrinsics, z)
        except NavError:
            break
        carried, inside = _carry(other, ones, hom, (x0, y0), size)
        if cv2.countNonZero(cv2.bitwise_and(mine, inside)) < count:
            break  # from here up, the other photo does not show it whole
        differ = cv2.absdiff(here, carried).astype(np.float64).sum(axis=2)
        heights.append(z)
        drawn.append(cv2.perspectiveTransform(back, hom).reshape(-1, 2).astype(np.float64))
        fits.append(float(differ[mine > 0].sum()) / count)
        if z >= top_m:
            break
        # the next plane draws the outline a quarter of a pixel further, at most
        step = min(1.0, top_m - z)
        try:
            ahead = plane_homography(other_pose, pose, intrinsics, z + step)
        except NavError:
            break
        moved = cv2.perspectiveTransform(back, ahead).reshape(-1, 2) - drawn[-1]
        per_m = float(np.max(np.hypot(*moved.T))) / step
        z = min(z + PARALLAX_PX / 8.0 / max(per_m, 1e-6), top_m)
    if not fits:
        return None
    best = int(np.argmin(fits))
    limit = fits[best] / GRAIN_RATIO

    def apart(i: int) -> float:
        return float(np.max(np.hypot(*(drawn[i] - drawn[best]).T)))

    answer = max(i for i in range(len(fits)) if fits[i] <= limit or apart(i) < PARALLAX_PX / 2.0)
    told = [i for i in range(answer + 1, len(fits)) if apart(i) - apart(answer) >= PARALLAX_PX]
    return heights[answer] if told else None


def _showing(other: npt.NDArray[np.uint8], hidden: CvArray | None) -> CvArray:
    """255 over ``other`` where it shows the ground (not ``hidden``), for `_carry`."""
    if hidden is not None:
        return cv2.bitwise_not(hidden)
    return np.full(other.shape[:2], 255, np.uint8)


def _carry(
    other: npt.NDArray[np.uint8],
    ones: CvArray,
    hom: npt.NDArray[np.float64],
    corner: tuple[int, int],
    size: tuple[int, int],
) -> tuple[CvArray, CvArray]:
    """``other`` carried by the plane homography ``hom`` into the box of ``size`` whose top
    left pixel is ``corner``, and where it reaches there (``ones``: 255 over ``other``)."""
    x0, y0 = corner
    shift = np.array([[1.0, 0.0, -x0], [0.0, 1.0, -y0], [0.0, 0.0, 1.0]]) @ hom
    carried = cv2.warpPerspective(other, shift, size, flags=cv2.INTER_LINEAR)
    return carried, cv2.warpPerspective(ones, shift, size, flags=cv2.INTER_NEAREST)


def _median(values: npt.NDArray[np.float64]) -> float:
    """``np.median`` of a 1-D array, without the import of numpy.ma it makes."""
    n = len(values)
    half = n // 2
    if n % 2:
        return float(np.partition(values, half)[half])
    part = np.partition(values, (half - 1, half))
    return float((part[half - 1] + part[half]) / 2.0)


def _near(image: npt.NDArray[np.uint8], rgb: tuple[int, int, int]) -> CvArray:
    lo = np.array([max(c - _NEAR_DN, 0) for c in rgb], np.uint8)
    hi = np.array([min(c + _NEAR_DN, 255) for c in rgb], np.uint8)
    return cv2.inRange(image, lo, hi)


def _shift_px(
    region: CvArray,
    pose: CameraPose,
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    z_m: float,
) -> float:
    """How far apart the ground's and the plane z = ``z_m``'s carrying put the region's
    pixels, at most (its outline's pixels suffice: the shift grows away from the nadir)."""
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return 0.0
    pts = np.concatenate([c[:, 0, :] for c in contours]).astype(np.float64)
    try:
        to_ground = np.linalg.inv(plane_homography(other_pose, pose, intrinsics, 0.0))
        at_z = plane_homography(other_pose, pose, intrinsics, z_m)
    except (NavError, np.linalg.LinAlgError):
        return 0.0
    # a pixel of this photo, carried back into the other as the ground, then here as z
    back = cv2.perspectiveTransform(pts.reshape(-1, 1, 2), to_ground)
    again = cv2.perspectiveTransform(back, at_z).reshape(-1, 2)
    return float(np.max(np.hypot(*(again - pts).T)))


def least_telling_m(
    region: CvArray,
    pose: CameraPose,
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    top_m: float,
) -> float | None:
    """The lowest of `HEIGHTS_M` (up to ``top_m``) whose drawing of the region the photos
    tell from the ground's: shifted by at least `PARALLAX_PX`."""
    for z in HEIGHTS_M:
        if z > top_m:
            return None
        if _shift_px(region, pose, other_pose, intrinsics, z) >= PARALLAX_PX:
            return z
    return None
