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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import cv2
import numpy as np

from uavtool.camera import project
from uavtool.mission.observations import Photo
from uavtool.nav import NavError, ground_polygon
from uavtool.nav.geometry import convex_hull
from uavtool.vision import Shape
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import ground_mask, hue_distance_deg, non_ground

Ring = tuple[tuple[float, float], ...]


class Unknown(NamedTuple):
    """Where a building of unknown height may stand, and the highest its roof may be."""

    footprint: Ring
    upper_m: float
    bands: tuple[tuple[Ring, float], ...] = ()
    """Where it stands for each range of heights still possible, with that range's top. A
    building as high as ``h`` stands under its roof's outline at ``h``, and the outline of a
    roof seen from one camera slides toward that camera's nadir as the roof is placed
    higher: over any one place only the heights that put the building there count. Empty:
    anywhere in ``footprint``, up to ``upper_m``."""

    def top_m(self, near: Callable[[Ring], bool]) -> float | None:
        """The highest this building may stand where ``near`` holds of where it would stand
        (None: nowhere)."""
        if not self.bands:
            return self.upper_m if near(self.footprint) else None
        return max((top for ring, top in self.bands if near(ring)), default=None)


@dataclass(slots=True)
class Overview:
    """The higher overview as the survey left it: its photo, its building shapes with each
    roof's height (None: not known, or known only for plans), its regions of what is not
    ground, and where a building of unknown height seen in it may stand (``place``:
    :func:`unknown_place` against the photos the survey took). A look taken later measures
    more of its roofs (`rest_of` tells what of a region that leaves unexplained)."""

    photo: Photo
    shapes: tuple[Shape, ...]
    roofs_m: list[float | None]
    regions: tuple[Shape, ...]
    place: Callable[[Shape], Unknown]
    params: VectorizeParams
    parts: tuple[Shape, ...] | None = None
    """``regions`` with what lies on the ground taken out (`ground.regions_off_ground`): a
    building of unknown height stands in its part of its region."""
    photos: tuple[Photo, ...] = ()
    """The survey's other photos from above (the lower overview, the tour's)."""
    others: dict[int, Shape] = field(default_factory=dict)
    """What is not ground and no building shape explains, of unknown height, by its key in
    the mission's ``unknown`` (negative): the survey's obstacles, and what of a region a
    roof measured later leaves unexplained."""

    def rest_of(self, index: int, roof_m: float) -> list[Shape]:
        """What of the region of shape ``index`` no roof explains once that roof is measured
        ``roof_m`` high: another building merged with it in the photo, of no building
        colour. A roof still of unknown height explains its whole region."""
        region = region_of(self.shapes[index], self.regions)
        if region is None:
            return []
        roofs = list(self.roofs_m)
        roofs[index] = roof_m
        inside = [i for i, s in enumerate(self.shapes) if region_of(s, [region]) is region]
        return unexplained(
            self.photo,
            [self.shapes[i] for i in inside],
            [roofs[i] or 0.0 for i in inside],
            [roofs[i] is not None for i in inside],
            [region],
            self.params,
            self.parts,
        )


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
    others: Sequence[Photo | Evidence],
    regions: Sequence[Shape],
    *,
    hue_tolerance_deg: float = 0.0,
) -> Unknown:
    """Where the building whose roof is ``shape`` (unmeasured) may stand, and the highest it
    may be: :func:`unknown_roof` of the roof, and of everything not ground around it in the
    photo (``regions``; its walls, a part of another colour, a neighbour touching it in the
    photo). A region cut by the frame may hold a higher roof beyond it: up to ``tallest_m``."""
    tol = hue_tolerance_deg
    place = unknown_roof(shape, photo, tallest_m, others, hue_tolerance_deg=tol)
    region = region_of(shape, regions)
    if region is None:
        return place
    if region.cut_by_border:  # a higher roof may lie beyond the frame, anywhere in it
        return Unknown(place.footprint, tallest_m)
    whole = unknown_roof(
        region, photo, tallest_m, others, hue_tolerance_deg=tol, own_rgb=shape.colour_rgb
    )
    return Unknown(
        tuple(convex_hull([*place.footprint, *whole.footprint])),
        max(place.upper_m, whole.upper_m),
        place.bands + whole.bands,
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


class Known(NamedTuple):
    """A roof of measured height: where it stands (ENU metres), how high, and its colour."""

    footprint: Ring
    roof_m: float
    colour_rgb: tuple[int, int, int]


class SeenRoof(NamedTuple):
    """A roof of known height as a photo shows it: its height, its colour, the mask of the
    pixels showing it (in its place for that height, and of its colour) and their box."""

    roof_m: float
    colour_rgb: tuple[int, int, int]
    mask: Any
    box: tuple[int, int, int, int]
    """x0, y0, x1, y1 (exclusive)."""


@dataclass(frozen=True, slots=True)
class Evidence:
    """A nadir photo as evidence of free space: where it sees the ground, and where it sees
    a roof of known height (:func:`evidence`)."""

    photo: Photo
    ground: Any
    roofs: tuple[SeenRoof, ...]


def evidence(photo: Photo, known: Sequence[Known] = (), *, tolerance_dn: float = 0.0) -> Evidence:
    """What ``photo`` (from above) shows of the ground, and of each roof of ``known``: the
    pixels in that roof's place at its height, within ``tolerance_dn`` of its colour in every
    channel."""
    k = photo.intrinsics
    ground = ground_mask(photo.image_rgb)
    roofs = []
    for footprint, roof_m, rgb in known:
        ring = _ring_px(footprint, roof_m, photo)
        if ring is None:
            continue
        x0, y0 = np.maximum(ring.min(axis=0), 0)
        x1, y1 = np.minimum(ring.max(axis=0) + 1, (k.width_px, k.height_px))
        if x0 >= x1 or y0 >= y1:
            continue
        place = np.zeros(ground.shape, np.uint8)
        cv2.fillPoly(place, [ring.reshape(-1, 1, 2)], 255)
        lo = np.clip(np.array(rgb) - tolerance_dn, 0, 255).astype(np.uint8)
        hi = np.clip(np.array(rgb) + tolerance_dn, 0, 255).astype(np.uint8)
        mask = cv2.bitwise_and(place, cv2.inRange(photo.image_rgb, lo, hi))
        roofs.append(SeenRoof(roof_m, rgb, mask, (int(x0), int(y0), int(x1), int(y1))))
    return Evidence(photo, ground, tuple(roofs))


def unknown_roof(
    shape: Shape,
    photo: Photo,
    tallest_m: float,
    others: Sequence[Photo | Evidence] = (),
    *,
    hue_tolerance_deg: float = 0.0,
    own_rgb: tuple[int, int, int] | None = None,
) -> Unknown:
    """Where a building of unknown height (up to ``tallest_m``) may stand: its roof's outline
    projected on every roof plane it may be at, from the ground up, and everything between;
    and the highest its roof may be. A height is ruled out where one of ``others`` (other
    nadir photos) sees what the building would stand on at that height: no building stands
    where a camera sees, whole, the ground beneath it, or its roof's place as ground. Nor
    where a camera sees, under it, a lower roof of known height (:func:`evidence`) of
    another colour than its own (``own_rgb``, else ``shape``'s; more than
    ``hue_tolerance_deg`` apart: one of its own colour may be a lower tier of the same
    building, its own roof in the photo). The roof may be up to a plane's step above the
    highest plane left (it was not tried)."""
    heights = [0.0]
    step_m = _HEIGHT_STEP_M
    while heights[-1] + step_m < tallest_m:
        heights.append(heights[-1] + step_m)
    heights.append(tallest_m)
    feet = [footprint_at(shape, photo, h) for h in heights]
    if others:
        hue = shape.colour_rgb if own_rgb is None else own_rgb
        views = [
            _other_colours(o if isinstance(o, Evidence) else evidence(o), hue, hue_tolerance_deg)
            for o in others
        ]
        kept = [
            (f, h)
            for f, h in zip(feet, heights, strict=True)
            if not any(
                _seen_beneath(f, h, v) or _ground_there(f, h, v.photo, v.ground) for v in views
            )
        ]
        if kept:  # every height ruled out: the photos disagree, keep them all
            feet, heights = [f for f, _ in kept], [h for _, h in kept]
    upper = min(max(heights) + _HEIGHT_STEP_M, tallest_m)
    # a roof between two planes lies between their outlines: each plane left stands for the
    # heights a step either side of it
    bands = tuple(
        (
            tuple(
                convex_hull(
                    [
                        *footprint_at(shape, photo, max(h - step_m, 0.0)),
                        *footprint_at(shape, photo, min(h + step_m, tallest_m)),
                    ]
                )
            ),
            min(h + step_m, tallest_m),
        )
        for h in heights
    )
    return Unknown(tuple(convex_hull([p for f in feet for p in f])), upper, bands)


_HEIGHT_STEP_M = 2.0
"""The roof planes a building of unknown height is placed on, this far apart."""
_GROUND_SEEN = 0.9
"""The share of a footprint's pixels in the other photo that must show what is beneath it
(or ground) to rule it out."""


def _other_colours(view: Evidence, rgb: tuple[int, int, int], tolerance_deg: float) -> Evidence:
    """``view`` with only the known roofs whose hue is more than ``tolerance_deg`` from
    ``rgb``'s."""
    roofs = tuple(r for r in view.roofs if hue_distance_deg(r.colour_rgb, rgb) > tolerance_deg)
    return Evidence(view.photo, view.ground, roofs)


def _ring_px(footprint: Sequence[tuple[float, float]], z_m: float, photo: Photo) -> Any:
    """``footprint`` at height ``z_m`` in ``photo``'s pixels (int32 (n, 2)), None when a
    corner is not in front of the camera."""
    if not z_m < photo.pose.pos_enu_m[2]:
        return None
    uvz = project(np.array([(x, y, z_m) for x, y in footprint]), photo.pose, photo.intrinsics)
    if not bool(np.all(uvz[:, 2] > 0.0)):
        return None
    return np.round(uvz[:, :2]).astype(np.int32)


def _whole(ring: Any, photo: Photo) -> bool:
    """Whether a pixel ring (:func:`_ring_px`) lies whole in ``photo``'s frame."""
    k = photo.intrinsics
    return bool(
        ring is not None
        and ring.min() >= 0
        and ring[:, 0].max() <= k.width_px - 1
        and ring[:, 1].max() <= k.height_px - 1
    )


def _filled(ring: Any, x0: int, y0: int, shape: tuple[int, int]) -> Any:
    """A mask of ``shape`` (rows, columns) whose pixel (0, 0) is the photo's (x0, y0), 255
    inside ``ring``."""
    mask = np.zeros(shape, np.uint8)
    cv2.fillPoly(mask, [(ring - (x0, y0)).reshape(-1, 1, 2)], 255)
    return mask


def _seen_beneath(footprint: tuple[tuple[float, float], ...], h_m: float, view: Evidence) -> bool:
    """Whether ``view`` sees, whole and over most of it, what lies beneath a building of
    ``footprint`` standing ``h_m`` tall: the ground at its base, or a roof lower than
    ``h_m`` where it would stand. What the camera sees lies in front of any building."""
    k = view.photo.intrinsics
    base = _ring_px(footprint, 0.0, view.photo)
    if not _whole(base, view.photo):
        return False
    planes = [(base, view.ground)]
    for roof in view.roofs:
        if not roof.roof_m < h_m:
            continue
        ring = _ring_px(footprint, roof.roof_m, view.photo)
        if ring is None:
            continue
        (x0, y0), (x1, y1) = ring.min(axis=0), ring.max(axis=0) + 1
        rx0, ry0, rx1, ry1 = roof.box
        if x1 > rx0 and rx1 > x0 and y1 > ry0 and ry1 > y0:
            planes.append((ring, roof.mask))
    rings = np.concatenate([ring for ring, _ in planes])
    x0, y0 = np.maximum(rings.min(axis=0), 0)
    x1, y1 = np.minimum(rings.max(axis=0) + 1, (k.width_px, k.height_px))
    shape = (int(y1 - y0), int(x1 - x0))
    area = cv2.countNonZero(_filled(base, x0, y0, shape))
    if area == 0:
        return False
    seen: Any = np.zeros(shape, np.uint8)
    for ring, mask in planes:
        there = _filled(ring, x0, y0, shape)
        seen = cv2.bitwise_or(seen, cv2.bitwise_and(there, mask[y0:y1, x0:x1]))
    return bool(cv2.countNonZero(seen) >= _GROUND_SEEN * area)


def _ground_there(
    footprint: tuple[tuple[float, float], ...], z_m: float, photo: Photo, ground: Any
) -> bool:
    """Whether ``photo`` sees ``footprint`` (at height ``z_m``) whole, and as ground."""
    ring = _ring_px(footprint, z_m, photo)
    if not _whole(ring, photo):
        return False
    (x0, y0), (x1, y1) = ring.min(axis=0), ring.max(axis=0) + 1
    inside = _filled(ring, x0, y0, (int(y1 - y0), int(x1 - x0)))
    area = cv2.countNonZero(inside)
    if area == 0:
        return False
    return cv2.countNonZero(cv2.bitwise_and(inside, ground[y0:y1, x0:x1])) >= _GROUND_SEEN * area


def unexplained(
    photo: Photo,
    shapes: Sequence[Shape],
    roofs_m: Sequence[float],
    measured: Sequence[bool],
    regions: Sequence[Shape],
    params: VectorizeParams,
    parts: Sequence[Shape] | None = None,
) -> list[Shape]:
    """What is not ground in a nadir ``photo``, in a region (of ``regions``: what is not
    ground, :func:`~uavtool.vision.vectorize.not_ground_regions`) holding a building the
    vectorizer found (``shapes``), but outside every such building as measured: its roof at
    the height measured (``roofs_m``, where ``measured``), its walls down to the ground. A
    building of unknown height explains its whole region: it may stand anywhere in it (in
    its part of it, of ``parts``, when given: the regions with what lies on the ground
    taken out, which is then no part of what is left unexplained). A taller tier of one
    colour whose roof lies beyond the frame, or a neighbour of a darker shade merged with a
    building, shows here."""
    p, k = params, photo.intrinsics
    touched = np.zeros((k.height_px, k.width_px), np.uint8)
    explained = np.zeros_like(touched)
    for shape, roof_m, ok in zip(shapes, roofs_m, measured, strict=True):
        region = region_of(shape, regions)
        if region is None:
            continue
        cv2.fillPoly(touched, [pixels(region.polygon_px)], 255)
        if ok and (roof_m <= 0.0 or not shape.cut_by_border):  # ground has no walls
            for ring in _prism_px(shape, photo, roof_m):  # one by one: overlaps stay filled
                cv2.fillPoly(explained, [ring], 255)
        else:
            part = None if parts is None else region_of(shape, parts)
            cv2.fillPoly(explained, [pixels((part or region).polygon_px)], 255)
    # Outlines are simplified (by up to rdp_epsilon_px) and denoised (a median of
    # denoise_px): a building's own edge may lie that far off.
    reach = math.ceil(p.rdp_epsilon_px) + p.denoise_px // 2 + 1
    kernel = np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)
    grown = cv2.dilate(explained, kernel)
    rest = cv2.bitwise_and(touched, cv2.bitwise_not(grown))
    if parts is not None:  # what lies on the ground is in no part, and explains itself
        off = np.zeros_like(touched)
        for part in parts:
            cv2.fillPoly(off, [pixels(part.polygon_px)], 255)
            for hole in part.holes_px:
                cv2.fillPoly(off, [pixels(hole)], 0)
        rest = cv2.bitwise_and(rest, cv2.dilate(off, kernel))
    if cv2.countNonZero(rest) < p.min_area_px:
        return []
    return [s for s in non_ground(photo.image_rgb, p, within=rest) if s.area_px >= p.min_area_px]


def _prism_px(shape: Shape, photo: Photo, roof_m: float) -> list[Any]:
    """The pixels a flat-roofed building shows in a nadir ``photo``: its roof (``shape``, at
    ``roof_m``), its base on the ground, and each wall between."""
    world = footprint_at(shape, photo, roof_m)
    base = project(np.array([(x, y, 0.0) for x, y in world]), photo.pose, photo.intrinsics)
    return _prism_rings(np.asarray(shape.polygon_px, np.float64), base[:, :2])


def _prism_rings(top: Any, bottom: Any) -> list[Any]:
    """A flat-roofed building's roof ``top`` and base ``bottom`` (pixel rings, vertex for
    vertex) and each wall between, as OpenCV draws them."""
    n = len(top)
    walls = [np.array([top[i], top[(i + 1) % n], bottom[(i + 1) % n], bottom[i]]) for i in range(n)]
    return [pixels(ring) for ring in (top, bottom, *walls)]


def shows_as(
    shape: Shape, photo: Photo, region: Shape, other: Photo, highest_m: float, *, least: float = 0.5
) -> bool:
    """Whether the building whose roof is ``shape`` in nadir ``photo`` can be what ``region``
    of another nadir photo (``other``) shows: at some roof height up to ``highest_m`` (every
    metre), the building seen from ``other`` — its roof, its walls down to the ground —
    covers at least ``least`` of the region. A region of walls whose roof lay beyond that
    photo's frame is shown so by its own building, and never by one standing elsewhere."""
    k = other.intrinsics
    want = np.zeros((k.height_px, k.width_px), np.uint8)
    cv2.fillPoly(want, [pixels(region.polygon_px)], 255)
    total = cv2.countNonZero(want)
    top_m = min(highest_m, other.pose.pos_enu_m[2] - 1.0, photo.pose.pos_enu_m[2] - 1.0)
    seen = np.zeros_like(want)
    for roof_m in np.arange(0.0, top_m + 1e-9, 1.0):
        world = np.array(footprint_at(shape, photo, float(roof_m)))
        if len(world) < 3:
            continue
        top = project(np.column_stack([world, np.full(len(world), roof_m)]), other.pose, k)
        base = project(np.column_stack([world, np.zeros(len(world))]), other.pose, k)
        seen[:] = 0
        for ring in _prism_rings(top[:, :2], base[:, :2]):  # one by one: overlaps stay filled
            cv2.fillPoly(seen, [ring], 255)
        if total and cv2.countNonZero(cv2.bitwise_and(seen, want)) >= least * total:
            return True
    return False


def pixels(polygon_px: Any) -> Any:
    """A ring of float pixels as OpenCV draws it: int32 ``(n, 1, 2)``."""
    return np.round(np.asarray(polygon_px)).astype(np.int32).reshape(-1, 1, 2)
