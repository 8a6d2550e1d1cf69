"""Where a building may stand when its height is not known, and what no measured roof
explains.

A roof's outline seen from above fixes its building only once its height is known: unknown,
it may be anywhere along the rays through its outline, from the ground up to just below the
camera. Other photos from above rule heights out (no building stands where a camera sees
the ground). What is not ground in a photo and lies outside every building as measured (a
taller tier whose roof is beyond the frame, a neighbour of a darker shade merged with it) is
a building of unknown height too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import cv2
import numpy as np

from uavtool.camera import project
from uavtool.mission.observations import Photo
from uavtool.nav import NavError, ground_polygon
from uavtool.nav.geometry import convex_hull
from uavtool.vision import Shape
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import ground_mask, non_ground


class Unknown(NamedTuple):
    """Where a building of unknown height may stand, and the highest its roof may be."""

    footprint: tuple[tuple[float, float], ...]
    upper_m: float


def footprint_at(shape: Shape, photo: Photo, roof_m: float) -> tuple[tuple[float, float], ...]:
    """Where the roof ``shape`` of a nadir ``photo`` stands (ENU metres) if it is ``roof_m``
    above home."""
    try:
        return ground_polygon(shape.polygon_px, photo.pose, photo.intrinsics, plane_z_m=roof_m)
    except NavError:  # a roof assumed above the camera: place it on the ground instead
        return ground_polygon(shape.polygon_px, photo.pose, photo.intrinsics, plane_z_m=0.0)


def unknown_place(
    shape: Shape,
    photo: Photo,
    tallest_m: float,
    others: Sequence[Photo],
    regions: Sequence[Shape],
) -> Unknown:
    """Where the building whose roof is ``shape`` (unmeasured) may stand, and the highest it
    may be: :func:`unknown_roof` of the roof, and of everything not ground around it in the
    photo (``regions``; its walls, a part of another colour, a neighbour touching it in the
    photo). A region cut by the frame may hold a higher roof beyond it: up to ``tallest_m``."""
    place = unknown_roof(shape, photo, tallest_m, others)
    region = region_of(shape, regions)
    if region is None:
        return place
    if region.cut_by_border:
        return Unknown(place.footprint, tallest_m)
    whole = unknown_roof(region, photo, tallest_m, others)
    return Unknown(
        tuple(convex_hull([*place.footprint, *whole.footprint])),
        max(place.upper_m, whole.upper_m),
    )


def region_of(shape: Shape, regions: Sequence[Shape]) -> Shape | None:
    """The region covering most of ``shape``'s pixels, at least half of them (None: none
    does). A roof's corners may lie on its region's outline, or just outside once both are
    simplified: its inside tells."""
    ring = np.round(np.asarray(shape.polygon_px, np.float64)).astype(np.int32)
    x0, y0 = ring.min(axis=0)
    w, h = ring.max(axis=0) - (x0, y0) + 1
    own = np.zeros((int(h), int(w)), np.uint8)
    cv2.fillPoly(own, [(ring - (x0, y0)).reshape(-1, 1, 2)], 255)
    area = cv2.countNonZero(own)
    best, best_n = None, 0
    for region in regions:
        there = np.zeros_like(own)
        outline = np.round(np.asarray(region.polygon_px, np.float64)).astype(np.int32)
        cv2.fillPoly(there, [(outline - (x0, y0)).reshape(-1, 1, 2)], 255)
        n = cv2.countNonZero(cv2.bitwise_and(own, there))
        if n > best_n:
            best, best_n = region, n
    return best if area > 0 and 2 * best_n >= area else None


def unknown_roof(
    shape: Shape, photo: Photo, tallest_m: float, others: Sequence[Photo] = ()
) -> Unknown:
    """Where a building of unknown height (up to ``tallest_m``) may stand: its roof's outline
    projected on every roof plane it may be at, from the ground up, and everything between;
    and the highest its roof may be. A height is ruled out where one of ``others`` (other
    nadir photos) sees, whole, the ground that the building would stand on at that height:
    no building stands where a camera sees the ground. The roof may be up to a plane's step
    above the highest plane left (it was not tried)."""
    heights = [0.0]
    step_m = _HEIGHT_STEP_M
    while heights[-1] + step_m < tallest_m:
        heights.append(heights[-1] + step_m)
    heights.append(tallest_m)
    feet = [footprint_at(shape, photo, h) for h in heights]
    if others:
        # Where a building stands, no camera above it sees the ground: neither on its base
        # nor where its roof would show.
        grounds = [(o, ground_mask(o.image_rgb)) for o in others]
        kept = [
            (f, h)
            for f, h in zip(feet, heights, strict=True)
            if not any(_ground_there(f, 0.0, o, g) or _ground_there(f, h, o, g) for o, g in grounds)
        ]
        if kept:  # every height ruled out: the photos disagree, keep them all
            feet, heights = [f for f, _ in kept], [h for _, h in kept]
    upper = min(max(heights) + _HEIGHT_STEP_M, tallest_m)
    return Unknown(tuple(convex_hull([p for f in feet for p in f])), upper)


_HEIGHT_STEP_M = 2.0
"""The roof planes a building of unknown height is placed on, this far apart."""
_GROUND_SEEN = 0.9
"""The share of a footprint's pixels in the other photo that must be ground to rule it out."""


def _ground_there(
    footprint: tuple[tuple[float, float], ...], z_m: float, photo: Photo, ground: Any
) -> bool:
    """Whether ``photo`` sees ``footprint`` (at height ``z_m``) whole, and as ground."""
    k = photo.intrinsics
    if not z_m < photo.pose.pos_enu_m[2]:
        return False
    uvz = project(np.array([(x, y, z_m) for x, y in footprint]), photo.pose, k)
    if not bool(np.all(uvz[:, 2] > 0.0)):
        return False
    us, vs = uvz[:, 0], uvz[:, 1]
    if us.min() < 0.0 or vs.min() < 0.0 or us.max() > k.width_px - 1 or vs.max() > k.height_px - 1:
        return False
    inside = np.zeros(ground.shape, np.uint8)
    cv2.fillPoly(inside, [np.round(uvz[:, :2]).astype(np.int32).reshape(-1, 1, 2)], 255)
    area = cv2.countNonZero(inside)
    if area == 0:
        return False
    return cv2.countNonZero(cv2.bitwise_and(inside, ground)) >= _GROUND_SEEN * area


def unexplained(
    photo: Photo,
    shapes: Sequence[Shape],
    roofs_m: Sequence[float],
    measured: Sequence[bool],
    regions: Sequence[Shape],
    params: VectorizeParams,
) -> list[Shape]:
    """What is not ground in a nadir ``photo``, in a region (of ``regions``: what is not
    ground, :func:`~uavtool.vision.vectorize.not_ground_regions`) holding a building the
    vectorizer found (``shapes``), but outside every such building as measured: its roof at
    the height measured (``roofs_m``, where ``measured``), its walls down to the ground. A
    building of unknown height explains its whole region: it may stand anywhere in it. A
    taller tier of one colour whose roof lies beyond the frame, or a neighbour of a darker
    shade merged with a building, shows here."""
    p, k = params, photo.intrinsics
    touched = np.zeros((k.height_px, k.width_px), np.uint8)
    explained = np.zeros_like(touched)
    for shape, roof_m, ok in zip(shapes, roofs_m, measured, strict=True):
        region = region_of(shape, regions)
        if region is None:
            continue
        cv2.fillPoly(touched, [pixels(region.polygon_px)], 255)
        if ok and not shape.cut_by_border:
            for ring in _prism_px(shape, photo, roof_m):  # one by one: overlaps stay filled
                cv2.fillPoly(explained, [ring], 255)
        else:
            cv2.fillPoly(explained, [pixels(region.polygon_px)], 255)
    # Outlines are simplified (by up to rdp_epsilon_px) and denoised (a median of
    # denoise_px): a building's own edge may lie that far off.
    reach = math.ceil(p.rdp_epsilon_px) + p.denoise_px // 2 + 1
    grown = cv2.dilate(explained, np.ones((2 * reach + 1, 2 * reach + 1), np.uint8))
    rest = cv2.bitwise_and(touched, cv2.bitwise_not(grown))
    if cv2.countNonZero(rest) < p.min_area_px:
        return []
    return [s for s in non_ground(photo.image_rgb, p, within=rest) if s.area_px >= p.min_area_px]


def _prism_px(shape: Shape, photo: Photo, roof_m: float) -> list[Any]:
    """The pixels a flat-roofed building shows in a nadir ``photo``: its roof (``shape``, at
    ``roof_m``), its base on the ground, and each wall between."""
    world = footprint_at(shape, photo, roof_m)
    base = project(np.array([(x, y, 0.0) for x, y in world]), photo.pose, photo.intrinsics)
    top, bottom = np.asarray(shape.polygon_px, np.float64), base[:, :2]
    n = len(top)
    walls = [np.array([top[i], top[(i + 1) % n], bottom[(i + 1) % n], bottom[i]]) for i in range(n)]
    return [pixels(ring) for ring in (top, bottom, *walls)]


def pixels(polygon_px: Any) -> Any:
    """A ring of float pixels as OpenCV draws it: int32 ``(n, 1, 2)``."""
    return np.round(np.asarray(polygon_px)).astype(np.int32).reshape(-1, 1, 2)
