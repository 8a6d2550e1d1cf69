"""What the overviews show that lies on the ground: lawns, roads, car parks, fields, the
ground itself in a colour. Not buildings, not points of interest, not obstacles — told by
parallax between two photos (`uavtool.nav.parallax`), not by colour or how common it is."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import cv2
import numpy as np

from uavtool.mission.observations import Photo
from uavtool.mission.unknown import pixels
from uavtool.nav.parallax import STOREY_M, least_telling_m, on_ground
from uavtool.vision import Shape
from uavtool.vision.vectorize import non_ground

if TYPE_CHECKING:
    from uavtool.mission.mission import SearchMission

CvArray = Any
_WALL_BAND_PX = 3
"""How far around a region its walls are looked for: past its blended edge."""
_GREY_SATURATION = 40
"""OpenCV saturation (0-255) under which a colour is grey: its walls are grey too."""
_WALL_HUE_HALF = 8
"""How far (OpenCV hue units, 2° each) a wall's hue may be from its roof's: the same paint,
shaded (as `uavtool.vision.vectorize.inner_walls` takes it)."""
_NEAR_DN = 30
"""A region is one colour when all but a shape's worth of its pixels lie this close (per
channel) to its colour: flat shading and a ground texture (`uavtool.nav.parallax`)."""


def lies_on_ground(
    m: SearchMission, shape: Shape, photo: Photo, other: Photo | None, *, one_colour: bool
) -> bool:
    """Whether ``shape`` (in nadir ``photo``) is ground, by parallax against ``other`` (a
    nadir photo from elsewhere): False when the two cannot tell. With ``one_colour`` (a
    region of everything that is not ground, which may join a building and a road it
    touches), only a region of one colour may be: else what it holds besides might stand."""
    if other is None:
        return False
    region = _mask(shape, photo)
    if shows_walls(photo, region, shape.colour_rgb, least_px=m.params.vectorize.min_edge_px):
        return False
    least = m.params.vectorize.min_area_px
    if one_colour:
        other_colour = cv2.bitwise_and(region, cv2.bitwise_not(_near(photo, shape.colour_rgb)))
        if cv2.countNonZero(other_colour) >= least:
            return False
    verdict = on_ground(
        region,
        shape.colour_rgb,
        photo.image_rgb,
        photo.pose,
        other.image_rgb,
        other.pose,
        photo.intrinsics,
        top_m=other.pose.pos_enu_m[2] - 1.0,
        least_px=least,
    )
    return verdict is True


def measured_flat(
    shape: Shape, photo: Photo, other: Photo, roof_m: float, *, least_px: float
) -> bool:
    """Whether a roof measured ``roof_m`` above home from ``photo`` and ``other`` lies lower
    than those two photos tell from the ground there (and they tell a storey, `STOREY_M`),
    and shows no walls (`shows_walls`, at least ``least_px`` pixels of them): a lawn, a
    painted area, measured like a roof, is ground."""
    region = _mask(shape, photo)
    if shows_walls(photo, region, shape.colour_rgb, least_px=least_px):
        return False
    least = least_telling_m(
        region,
        photo.pose,
        other.pose,
        photo.intrinsics,
        other.pose.pos_enu_m[2] - 1.0,
    )
    return least is not None and least <= STOREY_M and roof_m < least


def shows_walls(
    photo: Photo, region: CvArray, colour_rgb: tuple[int, int, int], *, least_px: float
) -> bool:
    """Whether at least ``least_px`` pixels just around ``region`` (a mask over ``photo``)
    show another shade of its colour: a building's walls, which perspective shows beside
    its roof (unless it stands straight below the camera). What lies on the ground has none;
    a lawn beside a building of its hue seems to, and is not taken for ground."""
    kernel = np.ones((2 * _WALL_BAND_PX + 1, 2 * _WALL_BAND_PX + 1), np.uint8)
    band = cv2.subtract(cv2.dilate(region, kernel), region)
    hsv = cv2.cvtColor(photo.image_rgb, cv2.COLOR_RGB2HSV)
    own = cv2.cvtColor(np.array([[colour_rgb]], np.uint8), cv2.COLOR_RGB2HSV)[0, 0]
    if int(own[1]) < _GREY_SATURATION:
        alike = hsv[:, :, 1] < _GREY_SATURATION
    else:
        d = np.abs(hsv[:, :, 0].astype(np.int16) - int(own[0]))
        alike = (np.minimum(d, 180 - d) <= _WALL_HUE_HALF) & (hsv[:, :, 1] >= _GREY_SATURATION)
    walls = (band > 0) & alike & (_near(photo, colour_rgb) == 0)
    return int(np.count_nonzero(walls)) >= least_px


def without_ground(
    m: SearchMission, regions: list[Shape], photo: Photo, others: list[Photo]
) -> tuple[list[Shape], int]:
    """``regions`` (of nadir ``photo``, not ground by colour) with what lies on the ground
    taken out, and how many were ground: a region whose own colour parallax against one of
    ``others`` shows on the ground has that colour's pixels cut from it, and what is left —
    a building standing on a lawn — is kept as the roofs `non_ground` finds in it."""
    least = m.params.vectorize.min_area_px
    kept: list[Shape] = []
    flat = 0
    for r in regions:
        if not any(lies_on_ground(m, r, photo, o, one_colour=False) for o in others):
            kept.append(r)
            continue
        flat += 1
        rest = cv2.bitwise_and(_mask(r, photo), cv2.bitwise_not(_near(photo, r.colour_rgb)))
        if cv2.countNonZero(rest) >= least:
            kept.extend(non_ground(photo.image_rgb, m.params.vectorize, within=rest))
    return kept, flat


def _mask(shape: Shape, photo: Photo) -> CvArray:
    region: CvArray = np.zeros(photo.image_rgb.shape[:2], np.uint8)
    cv2.fillPoly(region, [pixels(shape.polygon_px)], 255)
    for hole in shape.holes_px:
        cv2.fillPoly(region, [pixels(hole)], 0)
    return region


def _near(photo: Photo, rgb: tuple[int, int, int]) -> CvArray:
    lo = np.array([max(c - _NEAR_DN, 0) for c in rgb], np.uint8)
    hi = np.array([min(c + _NEAR_DN, 255) for c in rgb], np.uint8)
    return cv2.inRange(photo.image_rgb, lo, hi)
