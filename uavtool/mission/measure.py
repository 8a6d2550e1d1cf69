"""Roofs measured before any is flown near.

The two overviews measure only the roofs seen whole in both, and the lower one sees a smaller
area: most roofs away from home stay unmeasured, and an unmeasured roof may be taller than
``mission.assumed_roof_m`` (a tower). Before descending anywhere, the mission crosses at the
second overview's altitude — space the overview showed free: every roof in it is below the
camera — to above each point of interest whose roof is unknown, and photographs straight down.
Each such photo and the overview see the roofs from two places, so every roof whole in both is
triangulated, and one cut by a border is fitted by its visible edges
(:func:`uavtool.nav.heights.roof_from_cut_outline`). A roof whose outline in the overview no
tour photo agrees with (a taller neighbour's walls lean over part of it) is measured by two
tour photos that do agree (`measure_on_tour`). A roof measured taller than expected is
believed: as an obstacle, too tall is safe and too low is not.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING

import cv2
import numpy as np

from uavtool.mission.analysis import not_flat, placed_roof, roof_between
from uavtool.mission.ground import lies_on_ground, regions_off_ground, without_ground
from uavtool.mission.looks import photo_shapes
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest
from uavtool.mission.survey import (
    Obstacle,
    Survey,
    below_camera_m,
    points_of_interest,
    same_colour,
)
from uavtool.mission.unknown import (
    Known,
    Overview,
    Unknown,
    evidence,
    footprint_at,
    pixels,
    unexplained,
    unknown_place,
)
from uavtool.nav import NavError, frame_on_plane, ground_point
from uavtool.nav.geometry import segment_polygon_distance
from uavtool.nav.heights import roof_from_cut_outline
from uavtool.nav.parallax import STOREY_M
from uavtool.vision import Shape
from uavtool.vision.colour import has_hue, hue_distance_deg
from uavtool.vision.vectorize import non_ground, same_paint

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission

_AGREE = 0.25
"""How far apart the two photos may place one roof (at its height, as a share of the roof's
size in the first photo) for their outlines to count as the same roof: a centroid moves
with the roof's outline, a neighbour stands at least a safety margin away."""


def measure_from_above(m: SearchMission, seen: Survey, order: tuple[int, ...]) -> Wait[Survey]:
    """Photograph, from the overview's altitude, each point of interest (in ``order``) and
    then each obstacle whose roof is still unknown, measure every unknown roof against each
    photo, and return the survey with those roofs, footprints, points of interest and
    obstacles."""
    ceiling_m = seen.photo.pose.pos_enu_m[2]
    m.ceiling_m = ceiling_m
    m.seen_ground = frame_on_plane(seen.photo.pose, seen.photo.intrinsics)
    m.from_above = [seen.photo, *([] if seen.lower is None else [seen.lower])]
    below_m = ceiling_m - 1.0
    others = _unclassified(m, seen)  # obstacles of no building colour
    if (
        all(seen.measured)
        and not others
        and not unexplained(
            seen.photo, seen.shapes, seen.roofs_m, seen.measured, seen.regions, m.params.vectorize
        )
    ):
        m.roofs = tuple(zip(seen.footprints, seen.roofs_m, strict=True))
        return seen
    others_m: list[float | None] = [None] * len(others)
    if others and seen.lower is not None:
        lower = non_ground(seen.lower.image_rgb, m.params.vectorize)
        others_m = [
            measure_roof(m, o, seen.photo, seen.lower, lower, below_m=below_m) for o in others
        ]
    roofs, measured = list(seen.roofs_m), list(seen.measured)
    before = sum(measured)
    # Where to photograph from: over each point of interest, then each obstacle; a stop
    # whose roof an earlier photo measured is skipped.
    stops: list[tuple[str, str, PointOfInterest | None, int]] = [
        (f"point of interest {k}", f"measure-{k}", seen.pois[k], -1) for k in order
    ]
    stops += [(f"obstacle {j}", f"measure-obstacle-{j}", None, j) for j in range(len(others))]
    photos = [] if seen.lower is None else [seen.lower]  # nadir photos that show the ground
    sightings: dict[int, list[tuple[Photo, Shape]]] = {}  # unmeasured roofs the tour saw whole
    for what, tag, poi, j in stops:
        if poi is not None:
            if measured[poi.shape_index]:
                continue
            x, y = poi.pos_en_m
        else:
            if others_m[j] is not None:
                continue
            x, y = ground_point(*others[j].centroid_px, seen.photo.pose, seen.photo.intrinsics)
        yield from m.move((x, y, ceiling_m), seen.photo.pose.heading_deg, f"over {what}, measuring")
        photo = yield from m.photo(tag, -90.0)
        photos.append(photo)
        m.from_above.append(photo)
        shapes = photo_shapes(m, photo)
        for i, shape in enumerate(seen.shapes):
            if not measured[i]:
                roof = measure_roof(
                    m, shape, seen.photo, photo, shapes, below_m=below_m, cut_plans_only=True
                )
                if roof is None and not shape.cut_by_border:
                    tour = sightings.setdefault(i, [])
                    roof = measure_on_tour(m, shape, seen.photo, (photo, shapes), tour, below_m)
                if roof is not None:
                    roofs[i], measured[i] = roof, True
        if None in others_m:
            found_here = non_ground(photo.image_rgb, m.params.vectorize)
            others_m = [
                h
                if h is not None
                else measure_roof(m, o, seen.photo, photo, found_here, below_m=below_m)
                for o, h in zip(others, others_m, strict=True)
            ]
    assumed_m = m.params.mission.assumed_roof_m
    tallest_m = below_camera_m(m, seen.photo)
    # What the overviews could not tell from the ground (beyond the lower one, near the
    # point below both), the tour's photos, taken from beside it, may: a lawn, a road.
    ground = frozenset(
        i
        for i, s in enumerate(seen.shapes)
        if not (measured[i] and roofs[i] > STOREY_M)
        and lies_on_ground(m, s, seen.photo, photos, one_colour=False, beside=seen.shapes)
    )
    for i in ground:
        roofs[i], measured[i] = 0.0, True
    # What the roofs as measured do not explain (a taller part of a building, a neighbour
    # of a darker shade merged with it in the photo) is not measured: it may be as high as
    # its region allows. Ground explains only itself: a lawn of unknown height explained
    # its whole region, and a tower beside it was once left out of every obstacle when the
    # lawn was found to be ground.
    # A building of unknown height stands in its region's part off the ground: a lawn it
    # stands on is no part of it (nor a reason to count it cut by the frame).
    # What is left of a region, one colour at a time, may lie on the ground too: a road
    # joining a building to the frame's border is no part of the building.
    on_ground = [*seen.ground, *(seen.shapes[i] for i in ground)]
    standing = [
        (footprint_at(s, seen.photo, roofs[i]), roofs[i])
        for i, s in enumerate(seen.shapes)
        if measured[i] and roofs[i] > 0.0 and not s.cut_by_border
    ]
    parts = regions_off_ground(m, seen.photo, seen.regions, on_ground, photos, standing)
    later = unexplained(
        seen.photo, seen.shapes, roofs, measured, seen.regions, m.params.vectorize, parts
    )
    others += later
    others_m += _measured_by(m, later, seen.photo, photos, below_m)
    flat = 0
    if photos:
        still: list[tuple[Shape, float | None]] = []
        for o, h in zip(others, others_m, strict=True):
            kept, cut = without_ground(m, [o], seen.photo, photos)
            flat += cut
            if not cut:
                still.append((o, h))
            elif h is None:  # what stands on it, if anything, is still to be measured
                still += [(k, None) for k in kept]
            elif h > STOREY_M:  # measured standing: the parallax of its colour was not it
                still.append((o, h))
        others, others_m = [o for o, _ in still], [h for _, h in still]
    if ground or flat:
        m.event(
            Level.INFO,
            f"{len(ground) + flat} more region(s) lie on the ground (parallax between the "
            "overview and the photos from above): not buildings",
        )
    # Each photo is evidence of where nothing stands: the ground it sees, and the roofs of
    # known height (measured whole) it sees in their places.
    known = [
        Known(footprint_at(s, seen.photo, roofs[i]), roofs[i], s.colour_rgb)
        for i, s in enumerate(seen.shapes)
        if measured[i] and not s.cut_by_border
    ]
    tol = m.params.mission.roof_colour_tolerance_dn
    views = [evidence(v, known, tolerance_dn=tol) for v in photos]
    hue = m.params.vectorize.hue_tolerance_deg

    def place_of(o: Shape) -> Unknown:
        return unknown_place(o, seen.photo, tallest_m, views, parts, hue_tolerance_deg=hue)

    # What is not ground and has the target's hue, though the vectorizer kept no roof of it
    # (walls whose roof lies beyond the frame, a darker shade), may be the target: it is a
    # point of interest, looked at before any match is final, and an obstacle as every
    # building is.
    rivals: list[tuple[Shape, float | None]] = []
    rest: list[tuple[Shape, float | None]] = []
    for o, h in zip(others, others_m, strict=True):
        (rivals if may_be_target(m, o) else rest).append((o, h))
    shapes = seen.shapes + tuple(o for o, _ in rivals)
    roofs += [assumed_m if h is None else h for _, h in rivals]
    measured += [h is not None for _, h in rivals]
    at_first = seen.measured + (False,) * len(rivals)
    others, others_m = [o for o, _ in rest], [h for _, h in rest]
    if rivals:
        m.event(
            Level.INFO,
            f"{len(rivals)} regions of the target's hue show no roof (walls, a darker shade): "
            "points of interest too",
        )
    obstacles = tuple(
        Obstacle(o, assumed_m, False, *place_of(o))
        if h is None
        else Obstacle(o, h, True, footprint_at(o, seen.photo, h), h)
        for o, h in zip(others, others_m, strict=True)
    )
    if obstacles:
        m.event(
            Level.INFO,
            f"{len(obstacles)} obstacles no roof of a building colour explains (grey, a darker "
            "shade, a taller part): roofs "
            + ", ".join(f"{o.roof_m:.1f} m" if o.measured else "unknown" for o in obstacles),
        )
    places = [  # for the roofs still unknown, the tour's photos rule out more
        Unknown(footprint_at(s, seen.photo, roofs[i]), roofs[i])
        if measured[i] and not at_first[i]
        else Unknown(seen.footprints[i], roofs[i])
        if measured[i]
        else place_of(s)
        for i, s in enumerate(shapes)
    ]
    footprints = tuple(place.footprint for place in places)
    pois = points_of_interest(m, shapes, seen.photo, roofs, measured, footprints, ground)
    taller = [
        f"{poi.index} ({poi.roof_m:.1f} m)"
        for poi in pois
        if poi.roof_measured and poi.roof_m > assumed_m
    ]
    m.event(
        Level.INFO,
        f"roofs measured from above: {sum(measured) - before} more, {sum(measured)} of "
        f"{len(measured)}" + (f"; taller than expected: {', '.join(taller)}" if taller else ""),
    )
    m.roofs = tuple(
        (fp, roof) for fp, roof, ok in zip(footprints, roofs, measured, strict=True) if ok
    ) + tuple((o.footprint, o.roof_m) for o in obstacles if o.measured)
    m.unknown = {
        i: place for i, (place, ok) in enumerate(zip(places, measured, strict=True)) if not ok
    }
    # A roof cut by the overview's border was measured by the edges it shows: a tier of a
    # stepped tower so measured once came out 21 m low. Where it is flown near, it counts
    # as high as its region allows (one cut by the frame: as high as anything may be).
    m.unknown.update(
        {
            i: place_of(s)
            for i, (s, ok) in enumerate(zip(shapes, measured, strict=True))
            if ok and s.cut_by_border and not at_first[i] and i not in ground
        }
    )
    m.unknown.update(
        {
            -1 - j: Unknown(o.footprint, o.upper_m, o.bands)
            for j, o in enumerate(obstacles)
            if not o.measured
        }
    )
    m.overview = Overview(
        seen.photo,
        shapes,
        [None if i in m.unknown else roofs[i] for i in range(len(shapes))],
        seen.regions,
        place_of,
        m.params.vectorize,
        parts,
        tuple(photos),
        {-1 - j: o.shape for j, o in enumerate(obstacles) if not o.measured},
    )
    return replace(
        seen,
        shapes=shapes,
        roofs_m=tuple(roofs),
        measured=tuple(measured),
        footprints=footprints,
        uppers_m=tuple(place.upper_m for place in places),
        pois=pois,
        obstacles=obstacles,
        roofless=frozenset(range(len(seen.shapes), len(shapes))),
        on_ground=ground,
    )


def _measured_by(
    m: SearchMission, regions: list[Shape], photo: Photo, photos: list[Photo], below_m: float
) -> list[float | None]:
    """Each of ``regions`` (of nadir ``photo``) measured against the first of ``photos``
    (nadir, taken already) that shows its roof, as the tour measures obstacles; None where
    none does."""
    heights: list[float | None] = [None] * len(regions)
    for other in photos:
        if all(h is not None for h in heights):
            break
        found = non_ground(other.image_rgb, m.params.vectorize)
        heights = [
            h if h is not None else measure_roof(m, r, photo, other, found, below_m=below_m)
            for r, h in zip(regions, heights, strict=True)
        ]
    return heights


def may_be_target(m: SearchMission, region: Shape) -> bool:
    """Whether a region no colour class kept could still be the target: it has a hue (not
    grey, white or black) within the match's hue gate of the target's (any hue without a
    gate)."""
    if not has_hue(region.colour_rgb, m.params.vectorize):
        return False
    limit = m.params.mission.match_hue_tolerance_deg
    return limit <= 0 or hue_distance_deg(region.colour_rgb, m.target.colour_rgb) <= limit


def _unclassified(m: SearchMission, seen: Survey) -> list[Shape]:
    """The regions of the higher overview that are not ground (by its colour, nor by
    parallax: `lies_on_ground`) and are not a building the vectorizer found: a region that
    touches a found roof of its own paint (`same_paint`: a coloured roof and its walls, the
    roof's colour shaded, are one building), or lies mostly (half or more) inside the found
    outlines, is that building. A grey roof beside a lawn, whose simplified outline reaches
    a pixel into it, is not that lawn (a 20 m grey building was once left out of every
    obstacle so)."""
    k = seen.photo.intrinsics
    masks = []
    for s in seen.shapes:
        mask = np.zeros((k.height_px, k.width_px), np.uint8)
        cv2.fillPoly(mask, [pixels(s.polygon_px)], 255)
        for hole in s.holes_px:  # a courtyard is not its building: what stands in it is other
            cv2.fillPoly(mask, [pixels(hole)], 0)
        masks.append(mask)
    found = np.zeros((k.height_px, k.width_px), np.uint8)
    for mask in masks:
        cv2.bitwise_or(found, mask, dst=found)
    out: list[Shape] = []
    for region in non_ground(seen.photo.image_rgb, m.params.vectorize):
        if region.area_px < m.params.vectorize.min_area_px:
            continue
        if lies_on_ground(
            m, region, seen.photo, () if seen.lower is None else (seen.lower,), one_colour=True
        ):
            continue  # a road, a car park: ground of another colour
        own = np.zeros_like(found)
        cv2.fillPoly(own, [pixels(region.polygon_px)], 255)
        if 2 * cv2.countNonZero(cv2.bitwise_and(own, found)) >= cv2.countNonZero(own):
            continue
        paint = np.full((3, 3, 3), region.colour_rgb, np.uint8)  # its colour, as a picture
        if any(
            bool(same_paint(paint, s.colour_rgb)[1, 1])
            and cv2.countNonZero(cv2.bitwise_and(own, mask)) > 0
            for s, mask in zip(seen.shapes, masks, strict=True)
        ):
            continue
        out.append(region)
    return out


def measure_roof(
    m: SearchMission,
    shape: Shape,
    photo: Photo,
    other: Photo,
    others: tuple[Shape, ...],
    *,
    below_m: float,
    cut_plans_only: bool = False,
) -> float | None:
    """The height of the roof ``shape`` (in nadir ``photo``) from the same roof in another
    nadir photo (its ``others`` shapes): of its colour, and placed by both photos in one spot
    at the height found. Whole in both: triangulated; whole in one: fitted by the edges the
    other shows. None when no shape of the other photo agrees, or both are cut.

    ``cut_plans_only``: the caller takes the height of a roof cut in ``photo`` only to plan
    views, never as clearance; it may then come from the looser fit (the whole outline's
    edges on the cut one's), which finds the outline's height, a stepped tower's lowest
    tier."""
    k = photo.intrinsics
    limit_px = max(_AGREE * math.sqrt(shape.area_px), 2.0) * (1.0 + shape.cut_by_border)
    best: tuple[float, float] | None = None  # (disagreement px, height)
    for cand in others:
        if not same_colour(m, cand.colour_rgb, shape.colour_rgb):
            continue
        if shape.cut_by_border and cand.cut_by_border:
            continue
        if _apart_at_any_height(shape, photo, cand, other, below_m, limit_px):
            continue  # no height found could place both here: not worth a fit
        if not shape.cut_by_border and not cand.cut_by_border:
            roof = roof_between(shape, photo, cand, other)  # None: no one roof explains both
        else:
            whole, whole_photo, cut, cut_photo = (
                (shape, photo, cand, other) if cand.cut_by_border else (cand, other, shape, photo)
            )
            fit = partial(
                roof_from_cut_outline,
                whole_ring_px=whole.polygon_px.tolist(),
                whole_pose=whole_photo.pose,
                cut_ring_px=cut.polygon_px.tolist(),
                cut_pose=cut_photo.pose,
                intrinsics=k,
                max_m=below_m,
                whole_holes_px=[h.tolist() for h in whole.holes_px],
                cut_holes_px=[h.tolist() for h in cut.holes_px],
            )
            roof = fit()
            if roof is None and shape.cut_by_border and cut_plans_only:
                # a courtyard the border cuts open, walls one camera sees: edges the whole
                # outline lacks
                roof = fit(whole_on_cut=True)
        if roof is None or not 0.0 <= roof <= below_m:
            continue
        miss = _disagreement_px(shape, photo, cand, other, roof)
        if miss is not None and miss <= limit_px and (best is None or miss < best[0]):
            best = (miss, roof)
    return None if best is None else best[1]


def measure_on_tour(
    m: SearchMission,
    shape: Shape,
    photo: Photo,
    here: tuple[Photo, tuple[Shape, ...]],
    tour: list[tuple[Photo, Shape]],
    below_m: float,
) -> float | None:
    """The height of the roof ``shape`` (whole in the overview ``photo``) from two photos of
    the tour above the points of interest, when no tour photo agrees with the overview's
    outline: a taller neighbour's walls, leaning out in the overview, may hide part of it,
    and then one flat roof explains no pair that includes the overview. ``here`` is the new
    photo and its shapes; ``tour`` the roof's earlier sightings, which this one joins.

    The roof in ``here`` is the shape of its colour, whole, that the two photos' centroids
    place in one spot; the height is the one `roof_between` finds for it and an earlier
    sighting (one flat roof explains both outlines, nothing stands higher inside them), and
    only if the overview's centroid lies there too and no photo of it, the overview included,
    shows a part of it standing higher."""
    other, shapes = here
    limit_px = max(_AGREE * math.sqrt(shape.area_px), 2.0)
    found: tuple[float, Shape] | None = None  # (disagreement px, shape)
    for cand in shapes:
        if cand.cut_by_border or not same_colour(m, cand.colour_rgb, shape.colour_rgb):
            continue
        roof = placed_roof(shape, photo, cand, other)
        if roof is None or not 0.0 <= roof <= below_m:
            continue
        miss = _disagreement_px(shape, photo, cand, other, roof)
        if miss is not None and miss <= limit_px and (found is None or miss < found[0]):
            found = (miss, cand)
    if found is None:
        return None
    seen_here = found[1]
    for earlier, seen_there in tour:
        roof = roof_between(seen_there, earlier, seen_here, other)
        if roof is None or not 0.0 <= roof <= below_m:
            continue
        miss = _disagreement_px(shape, photo, seen_here, other, roof)
        if miss is None or miss > limit_px:
            continue
        # Flat in two photos is not flat: a stepped tower seen from straight above hides its
        # upper tiers' walls, and two such photos put its roof at its lowest tier. No photo
        # of it may show a part standing higher, the overview included.
        views = [(photo, shape), *tour]
        if not any(not_flat(s, view, roof, other, seen_here) for view, s in views):
            return roof
    tour.append((other, seen_here))
    return None


def _apart_at_any_height(
    shape: Shape, photo: Photo, cand: Shape, other: Photo, top_m: float, limit_px: float
) -> bool:
    """Whether `_disagreement_px` exceeds ``limit_px`` at every height in 0..``top_m``, so
    that no roof height found for the pair could pass it. Each photo's centroid, placed on
    the plane z = h, moves linearly with h: their distance is least where the gap between
    two lines is; over the camera's height above the ground, which is at least its height
    above the plane, it bounds the disagreement from below. False (fit it) when a centroid
    cannot be placed on both planes."""
    try:
        a0 = ground_point(*shape.centroid_px, photo.pose, photo.intrinsics)
        a1 = ground_point(*shape.centroid_px, photo.pose, photo.intrinsics, plane_z_m=top_m)
        b0 = ground_point(*cand.centroid_px, other.pose, other.intrinsics)
        b1 = ground_point(*cand.centroid_px, other.pose, other.intrinsics, plane_z_m=top_m)
    except NavError:
        return False
    gap = (a0[0] - b0[0], a0[1] - b0[1])
    change = (a1[0] - b1[0] - gap[0], a1[1] - b1[1] - gap[1])
    square = change[0] * change[0] + change[1] * change[1]
    s = 0.0 if square == 0.0 else -(gap[0] * change[0] + gap[1] * change[1]) / square
    s = min(1.0, max(0.0, s))
    least_m = math.hypot(gap[0] + s * change[0], gap[1] + s * change[1])
    camera_m = photo.pose.pos_enu_m[2]
    if not camera_m > 0.0:
        return False
    # a hair of room for rounding: at the limit, fit and let `_disagreement_px` judge
    return least_m * photo.intrinsics.fx_px / camera_m > limit_px * (1.0 + 1e-6) + 1e-6


def _disagreement_px(
    shape: Shape, photo: Photo, cand: Shape, other: Photo, roof_m: float
) -> float | None:
    """How far apart the two photos put the roof's centre on its own plane, in pixels of
    ``photo`` there (for a cut outline, its centroid is only roughly the roof's: the caller
    allows more)."""
    k = photo.intrinsics
    try:
        a = ground_point(*shape.centroid_px, photo.pose, k, plane_z_m=roof_m)
        b = ground_point(*cand.centroid_px, other.pose, other.intrinsics, plane_z_m=roof_m)
    except NavError:
        return None
    metres_per_px = (photo.pose.pos_enu_m[2] - roof_m) / k.fx_px
    return math.dist(a, b) / metres_per_px if metres_per_px > 0.0 else None


def measure_in_the_way(
    m: SearchMission, x: float, y: float, photo: Photo, shapes: tuple[Shape, ...]
) -> bool:
    """Measure the roofs of unknown height within the safety margin of (x, y) that the
    higher overview shows whole against ``photo``, a later look from above (its building
    ``shapes``), as the survey's tour measures them against its own photos: a roof placed
    at one height by both, or a region lying on the ground by parallax (against the
    survey's photos too: what a roof measured late leaves of its region was never tried
    against them). A look taken lower and elsewhere sees from another place than any of
    the tour's. Whether any was measured (the floor there may then be lower)."""
    ov = m.overview
    if ov is None:
        return False
    margin_m = m.params.viewpoints.safety_margin_m

    def near(ring: tuple[tuple[float, float], ...]) -> bool:
        return segment_polygon_distance((x, y), (x, y), ring) <= margin_m

    below_m = ov.photo.pose.pos_enu_m[2] - 1.0
    regions: tuple[Shape, ...] | None = None  # what is not ground in the look, if needed
    learnt = False
    for i, place in sorted(m.unknown.items()):
        if place.top_m(near) is None:
            continue
        if 0 <= i < len(ov.shapes):
            shape, against = ov.shapes[i], shapes
        elif i in ov.others:  # a region of no building colour: against the look's regions
            if regions is None:
                regions = non_ground(photo.image_rgb, m.params.vectorize)
            shape, against = ov.others[i], regions
        else:
            continue
        roof = None
        if not shape.cut_by_border:  # a roof measured by the edges a border left is no
            roof = measure_roof(m, shape, ov.photo, photo, against, below_m=below_m)  # floor
        if roof is None or roof <= STOREY_M:
            flat = lies_on_ground(
                m, shape, ov.photo, [photo, *ov.photos], one_colour=False, beside=ov.shapes
            )
            roof = 0.0 if flat else roof
        if roof is None:
            continue
        m.learn_roof(i, footprint_at(shape, ov.photo, roof), roof)
        m.event(
            Level.INFO,
            f"a building of unknown height near ({x:.1f}, {y:.1f}) measured at last: "
            + ("it lies on the ground" if roof == 0.0 else f"roof {roof:.1f} m above home"),
        )
        learnt = True
    return learnt
