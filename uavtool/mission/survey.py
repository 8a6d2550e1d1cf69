"""The survey: two overview photos from above home — the second at least
``mission.overview_climb_m`` higher, and high enough to see the whole search area — give every
building seen whole in both its roof height (its roof's size and place change with the
camera's height above it: :mod:`uavtool.nav.heights`), and from it the building's position and
size on the ground. The higher photo sees furthest; its shapes become the points of interest.
A building whose height could not be measured is assumed as tall as
``mission.assumed_roof_m`` until a closer look measures it."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from uavtool.camera import Intrinsics
from uavtool.mission.analysis import roof_between
from uavtool.mission.ground import lies_on_ground, measured_flat
from uavtool.mission.looks import photo_shapes
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest
from uavtool.mission.params import MissionParams
from uavtool.mission.unknown import Unknown, footprint_at, unknown_place
from uavtool.nav import ground_point, min_area_rect
from uavtool.nav.geometry import convex_hull, point_polygon_distance
from uavtool.vision import Shape
from uavtool.vision.shapes import cut_edges
from uavtool.vision.vectorize import hue_distance_deg, not_ground_regions

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


@dataclass(frozen=True, slots=True)
class Survey:
    """The higher overview ``photo``, its ``shapes``, and per shape its roof height above home
    (measured or assumed) and footprint on the ground (ENU metres; for a building of unknown
    height, everywhere it may stand)."""

    photo: Photo
    shapes: tuple[Shape, ...]
    roofs_m: tuple[float, ...]
    measured: tuple[bool, ...]
    footprints: tuple[tuple[tuple[float, float], ...], ...]
    pois: tuple[PointOfInterest, ...]
    uppers_m: tuple[float, ...]
    """Per shape, the highest its roof may be: the roof's height where measured, else the
    highest no photo rules out (:func:`unknown_place`)."""
    regions: tuple[Shape, ...]
    """The outlines of what is not ground in ``photo`` (:func:`not_ground_regions`)."""
    lower: Photo | None = None
    """The lower overview photo."""
    obstacles: tuple[Obstacle, ...] = ()
    """What else is not ground in the higher photo: buildings of no colour the vectorizer
    keeps (grey, white, black, a darker shade of another's colour)."""
    roofless: frozenset[int] = frozenset()
    """The shapes that are regions of the target's hue showing no roof (walls whose roof
    lay beyond the frame, a darker shade): points of interest whose look must show a
    building that explains them (:func:`~uavtool.mission.unknown.shows_as`)."""
    ground: tuple[Shape, ...] = ()
    """The shapes of a building colour in ``photo`` that the two overviews tell lie on the
    ground (lawns, roads): no buildings, not in ``shapes``."""
    on_ground: frozenset[int] = frozenset()
    """The indices of ``shapes`` that the photos taken later tell lie on the ground (their
    roofs measured at 0): no building, so no obstacle and no point of interest. A lawn as
    wide as the frame, kept as an obstacle of height 0, once left no room for any side
    photo."""

    @property
    def highest_roof_m(self) -> float:
        return max((*self.roofs_m, *(o.roof_m for o in self.obstacles)), default=0.0)


@dataclass(frozen=True, slots=True)
class Obstacle:
    """A region of the higher overview that is not ground and no building of a colour: its
    outline there, its roof's height (measured, or assumed ``mission.assumed_roof_m``) and
    where it stands (for an unknown height, everywhere it may)."""

    shape: Shape
    roof_m: float
    measured: bool
    footprint: tuple[tuple[float, float], ...]
    upper_m: float
    """The highest its roof may be (``roof_m`` when measured)."""
    bands: tuple[tuple[tuple[tuple[float, float], ...], float], ...] = ()
    """Where it stands for each range of heights, when not measured (`Unknown.bands`)."""

    @property
    def height_m(self) -> float:
        """Its height as an obstacle: the highest its roof may be."""
        return self.roof_m if self.measured else self.upper_m


def survey(m: SearchMission) -> Wait[Survey]:
    """Photograph the scene from the overview altitude and from ``overview_climb_m`` higher."""
    p = m.params.mission
    low = yield from m.photo("overview", -90.0)
    low_shapes = photo_shapes(m, low)
    x, y, _ = low.pose.pos_enu_m
    high_alt = overview_ceiling_m(p, low.intrinsics)
    heading = overview_heading_deg(m.last.heading_deg if m.last else 0.0)
    yield from m.move((x, y, high_alt), heading, "second overview position")
    high = yield from m.photo("overview-2", -90.0)
    ground: list[Shape] = []
    heights: dict[int, float | None] = {}

    def building(s: Shape, every: tuple[Shape, ...]) -> bool:
        h = heights[id(s)] = _measure(m, s, high, low, low_shapes)
        flat = h is not None and measured_flat(
            s, high, low, h, least_px=m.params.vectorize.min_edge_px, beside=every
        )
        if flat or lies_on_ground(m, s, high, (low,), one_colour=False, beside=every):
            ground.append(s)
            return False
        return True

    shapes = photo_shapes(m, high, keep=building)
    regions = tuple(
        r
        for r in not_ground_regions(high.image_rgb, m.params.vectorize)
        if not lies_on_ground(m, r, high, (low,), one_colour=True)
    )
    if ground:
        m.event(
            Level.INFO,
            f"{len(ground)} region(s) of a colour lie on the ground (parallax between the "
            "overviews): not buildings",
        )
    found = [heights[id(shape)] for shape in shapes]
    measured = [h is not None for h in found]
    roofs = [p.assumed_roof_m if h is None else h for h in found]
    places = [
        Unknown(footprint_at(s, high, h), h)
        if h is not None
        else unknown_place(s, high, below_camera_m(m, high), (low,), regions)
        for s, h in zip(shapes, found, strict=True)
    ]
    footprints = tuple(place.footprint for place in places)
    pois = points_of_interest(m, shapes, high, roofs, measured, footprints)
    known = sum(measured)
    m.event(
        Level.INFO,
        f"roof heights measured for {known} of {len(shapes)} buildings"
        + (f" (others assumed {p.assumed_roof_m:g} m)" if known < len(shapes) else ""),
    )
    uppers = tuple(place.upper_m for place in places)
    return Survey(
        high,
        shapes,
        tuple(roofs),
        tuple(measured),
        footprints,
        pois,
        uppers,
        regions,
        lower=low,
        ground=tuple(ground),
    )


def points_of_interest(
    m: SearchMission,
    shapes: tuple[Shape, ...],
    photo: Photo,
    roofs_m: list[float],
    measured: list[bool],
    footprints: tuple[tuple[tuple[float, float], ...], ...],
    ground: frozenset[int] = frozenset(),
) -> tuple[PointOfInterest, ...]:
    """A point of interest per shape of the overview ``photo`` large enough for a building
    and not on the ground (``ground``: their indices).
    An unmeasured roof is assumed tall where that is the safe guess (``roofs_m``, for
    altitudes), and as high as the measured ones are (their median) where the best guess is
    (its position)."""
    p = m.params.mission
    known_m = sorted(h for h, ok in zip(roofs_m, measured, strict=True) if ok)
    typical_m = known_m[len(known_m) // 2] if known_m else 0.0
    pois: list[PointOfInterest] = []
    limit = p.match_hue_tolerance_deg
    for i, shape in enumerate(shapes):
        if i in ground:
            continue
        like_target = limit <= 0 or hue_distance_deg(shape.colour_rgb, m.target.colour_rgb) <= limit
        if shape.area_px < p.min_poi_area_px and not (shape.cut_by_border or like_target):
            continue  # too small for a building; one cut by the border may be any size, and
            # one of the target's colour may be a small target
        u, v = shape.centroid_px
        plane_m = roofs_m[i] if measured[i] else typical_m
        pos = ground_point(u, v, photo.pose, photo.intrinsics, plane_z_m=plane_m)
        extent = _extent_m(footprints[i])
        pois.append(
            PointOfInterest(
                len(pois), i, pos, shape.colour_rgb, shape.area_px, roofs_m[i], measured[i], extent
            )
        )
    return tuple(pois)


def overview_heading_deg(heading_deg: float) -> float:
    """The heading the overviews are taken facing: the one of north, east, south and west
    nearest ``heading_deg``. The photo's sides then run along the search square's (east,
    west, north and south of home), whichever way the vehicle faced at take-off; turned
    45°, a photo would leave the square's corners out."""
    return (round(heading_deg / 90.0) % 4) * 90.0


def overview_ceiling_m(p: MissionParams, intrinsics: Intrinsics) -> float:
    """The second overview's altitude above home (looks never climb above it)."""
    return max(p.overview_alt_m + p.overview_climb_m, search_altitude_m(p, intrinsics))


def search_altitude_m(p: MissionParams, intrinsics: Intrinsics) -> float:
    """The altitude from which a nadir photo over home, facing `overview_heading_deg`, sees
    the whole search area up to the tallest roof expected (``mission.assumed_roof_m``): a
    roof at the square's edge is that much nearer the camera than the ground, so it leaves
    the frame first. (Turned by the heading tolerance, a few degrees, the photo cuts a
    sliver off the square's corners: a building there is still seen, cut by the border.)"""
    half_fov = math.radians(min(intrinsics.hfov_deg, intrinsics.vfov_deg)) / 2.0
    return p.search_radius_m / math.tan(half_fov) + p.assumed_roof_m


def _measure(
    m: SearchMission, shape: Shape, high: Photo, low: Photo, low_shapes: tuple[Shape, ...]
) -> float | None:
    """The roof height of ``shape`` (in the higher photo) from the same roof in the lower
    one: same colour, whole in both, where the vertical climb puts it."""
    if shape.cut_by_border:
        return None
    p = m.params.mission
    k = high.intrinsics
    best: tuple[float, Shape] | None = None
    for other in low_shapes:
        if other.cut_by_border or not same_colour(m, other.colour_rgb, shape.colour_rgb):
            continue
        # Climbing straight up, a roof's offset from the image centre shrinks as its size
        # does: where the lower photo should show this roof, given its size there.
        ratio = math.sqrt(other.area_px / shape.area_px)
        u = k.cx_px + (shape.centroid_px[0] - k.cx_px) * ratio
        v = k.cy_px + (shape.centroid_px[1] - k.cy_px) * ratio
        miss = math.hypot(other.centroid_px[0] - u, other.centroid_px[1] - v)
        if miss <= p.roof_match_px and (best is None or miss < best[0]):
            best = (miss, other)
    if best is None:
        return None
    return roof_between(best[1], low, shape, high)


def same_colour(m: SearchMission, a_rgb: tuple[int, int, int], b_rgb: tuple[int, int, int]) -> bool:
    """Whether two outlines' colours can be one roof's (``mission.roof_colour_tolerance_dn``
    in every channel)."""
    tol = m.params.mission.roof_colour_tolerance_dn
    return all(abs(a - b) <= tol for a, b in zip(a_rgb, b_rgb, strict=True))


def same_building(m: SearchMission, seen: Survey, target: int) -> frozenset[int]:
    """``target`` and the survey's other measured roofs of its colour that touch it: the
    roofs of one stepped building, split in the overview by the walls between its tiers,
    are not obstacles to photographing it. Touching is within ``_TOUCHING_M``: another
    building of the colour in a dense block stands further off, and must stay an obstacle
    (one 2.7 m away, taken for a tier, once had a side photo planned into it); so must a
    roof of unknown height, which may stand anywhere along its rays."""
    own = seen.footprints[target]
    colour = seen.shapes[target].colour_rgb
    parts = {target}
    for i, shape in enumerate(seen.shapes):
        if i == target or not seen.measured[i] or not same_colour(m, shape.colour_rgb, colour):
            continue
        other = seen.footprints[i]
        gap = min(
            *(point_polygon_distance(q, own) for q in other),
            *(point_polygon_distance(q, other) for q in own),
        )
        if gap <= _TOUCHING_M:
            parts.add(i)
    return frozenset(parts)


_TOUCHING_M = 1.0
"""How far apart two roofs' footprints may be for the roofs to be one building's: tiers
meet (their footprints, each at its own measured height, touch but for the error of the
measurement)."""


def building_top_m(seen: Survey, parts: frozenset[int]) -> float:
    """The highest measured roof among a building's ``parts`` (survey shape indices), 0
    when none is measured."""
    return max((seen.roofs_m[i] for i in parts if seen.measured[i]), default=0.0)


def obstacles_around(
    m: SearchMission, seen: Survey, target: int
) -> list[tuple[tuple[tuple[float, float], ...], float]]:
    """The survey's footprints of every building but the target (and its other roofs), and
    of everything else that is not ground, each with its roof's height (where not measured,
    the highest it may be)."""
    skip = same_building(m, seen, target) | seen.on_ground
    return [(f, seen.uppers_m[i]) for i, f in enumerate(seen.footprints) if i not in skip] + [
        (o.footprint, o.height_m) for o in seen.obstacles
    ]


def beyond_the_frame(seen: Survey) -> list[tuple[tuple[float, float], ...]]:
    """Where the buildings cut by the overview's border may go on: each one's footprint swept
    out of the photo across every edge of the frame it touches, as far as any flight goes
    (1 km)."""
    photo = seen.photo
    k = photo.intrinsics
    centre = ground_point(k.cx_px, k.cy_px, photo.pose, k)
    edges = {
        "left": (0.0, k.cy_px),
        "right": (k.width_px - 1.0, k.cy_px),
        "top": (k.cx_px, 0.0),
        "bottom": (k.cx_px, k.height_px - 1.0),
    }
    out = []
    for i, (shape, footprint) in enumerate(zip(seen.shapes, seen.footprints, strict=True)):
        if not shape.cut_by_border or len(footprint) < 3 or i in seen.on_ground:
            continue
        swept = list(footprint)
        for edge in cut_edges((shape,), k):
            ex, ey = ground_point(*edges[edge], photo.pose, k)
            n = math.hypot(ex - centre[0], ey - centre[1])
            dx, dy = 1000.0 * (ex - centre[0]) / n, 1000.0 * (ey - centre[1]) / n
            swept += [(x + dx, y + dy) for x, y in footprint]
        out.append(tuple(convex_hull(swept)))
    return out


def remeasured_obstacles(
    m: SearchMission, seen: Survey, target: int, photo: Photo, shapes: tuple[Shape, ...]
) -> list[tuple[tuple[tuple[float, float], ...], float]]:
    """The footprints of every building but ``target`` (and its other roofs), each with its
    roof's height (where not measured, the highest it may be), those of unknown height
    measured again against a later nadir ``photo`` (its ``shapes``) where it shows them
    whole."""
    p = m.params.mission
    skip = same_building(m, seen, target) | seen.on_ground
    out = [(o.footprint, o.height_m) for o in seen.obstacles]
    for i, shape in enumerate(seen.shapes):
        if i in skip:
            continue
        footprint = seen.footprints[i]
        height = seen.uppers_m[i]
        if not seen.measured[i] and not shape.cut_by_border:
            roof = _measure_against(m, shape, seen.photo, photo, shapes)
            if roof is not None and roof <= p.assumed_roof_m + p.min_above_roof_m:
                footprint, height = footprint_at(shape, seen.photo, roof), roof
        out.append((footprint, height))
    return out


def _measure_against(
    m: SearchMission, shape: Shape, photo: Photo, other: Photo, others: tuple[Shape, ...]
) -> float | None:
    """The roof height of ``shape`` (in ``photo``) triangulated with the same roof in another
    nadir photo: its colour, whole, nearest where it falls on the ground."""
    k = photo.intrinsics
    here = ground_point(*shape.centroid_px, photo.pose, k)
    best: tuple[float, Shape] | None = None
    for cand in others:
        if cand.cut_by_border or not same_colour(m, cand.colour_rgb, shape.colour_rgb):
            continue
        there = ground_point(*cand.centroid_px, other.pose, other.intrinsics)
        miss = math.dist(here, there)
        if miss <= m.params.viewpoints.max_distance_m and (best is None or miss < best[0]):
            best = (miss, cand)
    return None if best is None else roof_between(shape, photo, best[1], other)


def below_camera_m(m: SearchMission, photo: Photo) -> float:
    """The tallest a roof seen in a nadir ``photo`` may be, when nothing measured it: a roof
    is below the camera (by the least clearance a look keeps over a roof); ``assumed_roof_m``
    is a guess, and a tower may stand taller (a roof's outline seen from above lies nearer
    the camera's nadir the taller it is)."""
    return photo.pose.pos_enu_m[2] - m.params.mission.min_above_roof_m


def _extent_m(footprint: tuple[tuple[float, float], ...]) -> float:
    rect = min_area_rect(footprint)
    return math.hypot(rect.length_m, rect.width_m)
