"""The side photos for the model, and what they teach about the building.

A side photo is taken from its planned viewpoint with a horizontal camera. While the building
touches the photo's border, it is taken again (up to ``mission.max_looks`` photos):

* cut by the top of the frame only: the building is taller than assumed. The photo proves it
  reaches at least the top of the view over its near wall; the plan is made again for one and
  a half times that height (the camera halfway up, as far off as the view then needs), from
  the same direction, with the same rules (safety margin, line of sight), and every later
  move crosses above it. A stepped tower whose outline from above is its lowest tier's gets
  its height this way.
* otherwise (cut at a side, or no plan fits): the camera backs away from the building by half
  the planned distance, as long as that keeps the safety margin from every other building.

Where the survey saw a building cut by its photo's border, that building may go on beyond
it: a viewpoint moved from where it was first planned keeps clear of all that too.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.mission.looks import photo_shapes
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level
from uavtool.mission.peek import peek
from uavtool.nav import Rect, Viewpoint, ViewpointFailure, ViewpointParams, plan_towards
from uavtool.nav.geometry import point_polygon_distance
from uavtool.nav.viewpoints import farther, foot_hidden, for_building
from uavtool.vision import Shape
from uavtool.vision.model3d import View, same_colour
from uavtool.vision.shapes import EDGE_PX, cut_edges

if TYPE_CHECKING:
    from collections.abc import Callable

    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission

# Hue window for "the same building" in the side photos (walls are shaded darker than roofs).
SIDE_HUE_TOLERANCE_DEG = 15.0
_TALLER = 1.5  # a building proved at least h tall is planned for as 1.5 h tall

Ring = tuple[tuple[float, float], ...]


@dataclass(slots=True)
class SidePlan:
    """What the side photos are planned from, and what they learn on the way.

    ``obstacles``: the other buildings' footprints, planned around; ``cautious``: those and
    the survey's cautious footprints, which backing away keeps clear of; ``unknown``: where
    the buildings the survey saw cut by its border may go on, which every viewpoint not
    planned at first (further, or for a photo not planned at first) keeps clear of too;
    ``params``: the viewpoint parameters, whose assumed height grows when a photo shows the
    building taller; ``transit_m``: the altitude every move crosses at, raised with it.
    """

    rect: Rect
    obstacles: list[Ring]
    cautious: list[Ring]
    unknown: list[Ring]
    intrinsics: Intrinsics
    params: ViewpointParams
    transit_m: float
    grown: bool = False
    """A photo showed the building taller than the viewpoints were first planned for."""
    heights: list[float] = dataclasses.field(default_factory=list)
    """Each of ``obstacles``' roof heights (``math.inf`` where not measured): a camera
    looking down may see the building's top over a lower one. Empty: as tall as any."""
    height_known: bool = False
    """The building's height was measured: no part of it stands above the height planned
    for (``params.assumed_height_m``)."""

    def sight(self) -> tuple[list[Ring], list[float] | None]:
        """The footprints a camera must see past, with their heights (None: unknown)."""
        footprints = self.obstacles + self.unknown
        if not self.heights:
            return footprints, None
        return footprints, self.heights + [math.inf] * len(self.unknown)

    def taller(self, m: SearchMission, height_m: float) -> None:
        """Plan from now on for a building ``height_m`` tall."""
        self.params = _for_height(m, self, height_m)
        self.grown = True
        clear_m = height_m + m.params.viewpoints.safety_margin_m + m.params.mission.arrive_radius_m
        self.transit_m = max(self.transit_m, clear_m)
        m.transit_m = max(m.transit_m or 0.0, self.transit_m)

    def again(self, m: SearchMission, vp: Viewpoint) -> Viewpoint:
        """``vp`` planned again from its direction for the height learnt since (``vp`` itself
        when nothing was learnt, or no viewpoint fits)."""
        if not self.grown:
            return vp
        found = _towards(self, vp, self.params)
        if not isinstance(found, Viewpoint):
            return vp
        m.event(
            Level.INFO,
            f"{vp.name} viewpoint: planned again for a {self.params.assumed_height_m:.1f} m "
            f"building: {found.distance_m:.1f} m off, {found.pos_enu_m[2]:.1f} m up",
        )
        return found


@dataclass(frozen=True, slots=True)
class HandedSide:
    """A side photo another vehicle takes meanwhile: its ``name`` (front, right) and a way
    to wait for it (``collect``: its view and the viewpoint it was taken from, or None when
    it brought none)."""

    name: str
    collect: Callable[[], Wait[tuple[View, Viewpoint] | None]]


def _for_height(m: SearchMission, plan: SidePlan, height_m: float) -> ViewpointParams:
    return for_building(plan.params, height_m, least_alt_m=m.params.viewpoints.camera_alt_m)


def _towards(
    plan: SidePlan, vp: Viewpoint, params: ViewpointParams
) -> Viewpoint | ViewpointFailure:
    cx, cy = plan.rect.center_en
    direction = (vp.pos_enu_m[0] - cx, vp.pos_enu_m[1] - cy)
    footprints, heights = plan.sight()
    return plan_towards(
        vp.name, plan.rect, direction, footprints, plan.intrinsics, params, vp.fallback, heights
    )


def side_view(
    m: SearchMission,
    plan: SidePlan,
    vp: Viewpoint,
    colour_rgb: tuple[int, int, int],
    *,
    fresh: bool = False,
    climb: bool = True,
) -> Wait[tuple[View, Viewpoint] | None]:
    """A side photo from ``vp`` — planned again first if the building proved taller since,
    unless ``fresh`` (planned with the plan's parameters as they are) — and the viewpoint it
    was finally taken from (see the module doc for the photos taken again), climbed back to
    the plan's transit altitude unless not ``climb`` (the caller climbs). None when ``vp`` lies
    beyond the ground the overview saw and a look down from the ceiling shows a building may
    stand within the margin of it."""
    p = m.params.mission
    if not fresh:
        vp = plan.again(m, vp)
    x, y, z = vp.pos_enu_m
    step_m = vp.distance_m * 0.5  # backing away: half the planned distance at a time
    if not m.over_seen_ground(x, y) and not (
        yield from peek(m, x, y, f"{vp.name} viewpoint", f"peek-{vp.name}")
    ):
        return None
    yield from m.travel(
        (x, y, plan.transit_m), vp.heading_deg, plan.transit_m, f"above the {vp.name} viewpoint"
    )
    for attempt in range(1, p.max_looks + 1):
        yield from m.move((x, y, z), vp.heading_deg, f"{vp.name} viewpoint")
        photo = yield from m.photo(
            vp.name if attempt == 1 else f"{vp.name}-{attempt}", vp.pitch_deg
        )
        shapes = photo_shapes(m, photo, nadir=False)
        silhouette = _in_line(
            same_colour(shapes, colour_rgb, hue_tolerance_deg=SIDE_HUE_TOLERANCE_DEG),
            plan.rect,
            photo,
            plan.params.assumed_height_m,
            clip=plan.height_known,
        )
        edges = cut_edges(silhouette, photo.intrinsics)
        if not edges or attempt == p.max_looks:
            break
        taller = _taller_view(m, plan, vp, photo.pose) if edges == {"top"} else None
        moved = taller if taller is not None else _backed_away(m, plan, vp, step_m)
        if moved is None:
            moved = _looking_down_instead(m, plan, vp)
        if moved is None:
            break
        # Up, across and down again: the way may pass a building the plan did not know.
        yield from m.move(
            (photo.pose.pos_enu_m[0], photo.pose.pos_enu_m[1], plan.transit_m), None, "climb"
        )
        nx, ny, _ = moved.pos_enu_m
        if not m.over_seen_ground(nx, ny) and not (
            yield from peek(m, nx, ny, f"{vp.name} viewpoint", f"peek-{vp.name}-{attempt + 1}")
        ):
            assert m.ceiling_m is not None  # peek crossed at it: back the same way
            yield from m.move((x, y, m.ceiling_m), None, f"back over the {vp.name} viewpoint")
            break
        vp = moved
        x, y, z = vp.pos_enu_m
        yield from m.travel((x, y, z), vp.heading_deg, plan.transit_m, f"{vp.name} viewpoint")
    if climb:  # else the caller climbs, from where the photo was taken
        yield from m.move(
            (x, y, plan.transit_m), vp.heading_deg, f"climb from the {vp.name} viewpoint"
        )
    footprints, heights = plan.sight()
    hidden = heights is not None and foot_hidden(
        photo.pose.pos_enu_m, plan.rect.corners(), footprints, heights
    )
    if hidden:
        m.event(Level.INFO, f"{vp.name} photo: the building's foot is hidden behind its neighbours")
    elif edges == {"bottom"}:
        # No room for a view of the whole height: the photo says nothing below the frame,
        # as below a foot hidden behind a neighbour, and the top photo bounds the rest.
        hidden = True
        m.event(Level.INFO, f"{vp.name} photo: the building's foot is below the frame")
    return View(silhouette, photo.pose, photo.intrinsics, foot_hidden=hidden), vp


def _in_line(
    shapes: tuple[Shape, ...], rect: Rect, photo: Photo, height_m: float, *, clip: bool = False
) -> tuple[Shape, ...]:
    """The shapes that overlap where the building stands in the photo: the outline, in the
    image, of its footprint's box from the ground up to ``height_m`` (a camera looking down
    sees the box's sides converge, so no span of columns tells), grown by a tenth each way:
    those mostly inside it (``_IN_VIEW``). A building of a close colour beside or far behind
    it is not part of its silhouette. All of them when none is, or the camera stands over
    the footprint. With ``clip`` (the height is measured), a shape cut by the frame and
    reaching out of the box is cut back to it: past it, the photo merged another building
    of its colour with it (towers stand behind one another, seen from above)."""
    corners = np.array(
        [(x, y, z) for z in (0.0, height_m) for x, y in rect.corners()], dtype=np.float64
    )
    uvz = project(corners, photo.pose, photo.intrinsics)
    if np.any(uvz[:, 2] <= 0.0):
        return shapes
    raw = shapely.MultiPoint([(float(u), float(v)) for u, v, _ in uvz]).convex_hull
    lo_u, lo_v, hi_u, hi_v = raw.bounds
    size = max(hi_u - lo_u, hi_v - lo_v)
    box = raw.buffer(0.1 * size)
    kept = tuple(s for s in shapes if _share_inside(s, box) >= _IN_VIEW) or shapes
    if not clip:
        return kept
    # Cut back nearer the box than the tenth that tells which shapes are the building's:
    # where the box lies inside the frame and a shape reaches the frame's edge beyond it,
    # a building of its colour merged with it there (a tower behind it rising out of the
    # frame), and the building itself is whole.
    grow = _CLIP_GROWTH * size
    near = shapely.box(lo_u - grow, lo_v - grow, hi_u + grow, hi_v + grow)
    return tuple(
        part for s in kept for part in _clipped(s, box.intersection(near), photo.intrinsics)
    )


def _clipped(shape: Shape, box: shapely.Polygon, k: Intrinsics) -> tuple[Shape, ...]:
    """``shape`` cut back to ``box`` (image pixels) when it is cut by the frame and reaches
    out of the box; else itself."""
    if not shape.cut_by_border:
        return (shape,)
    outline = shapely.Polygon(shape.polygon_px, list(shape.holes_px)).buffer(0)
    if outline.within(box):
        return (shape,)
    inside = outline.intersection(box)
    parts = [g for g in getattr(inside, "geoms", [inside]) if isinstance(g, shapely.Polygon)]
    out = []
    for part in parts:
        if part.area <= 0.0:
            continue
        ring = np.asarray(part.exterior.coords[:-1], dtype=np.float64)
        lo, hi = ring.min(axis=0), ring.max(axis=0)
        edge = EDGE_PX
        cut = bool(
            lo[0] <= edge
            or lo[1] <= edge
            or hi[0] >= k.width_px - 1 - edge
            or hi[1] >= k.height_px - 1 - edge
        )
        holes = tuple(np.asarray(r.coords[:-1], dtype=np.float64) for r in part.interiors)
        out.append(
            Shape.from_rings(
                colour_rgb=shape.colour_rgb, polygon_px=ring, holes_px=holes, cut_by_border=cut
            )
        )
    return tuple(out) or (shape,)


_CLIP_GROWTH = 0.03
"""How far past the building's box in the photo (its height measured), as a share of the
box's size, a shape cut by the frame is kept: the box's error (the footprint and height
measured, ~1 m, a few pixels) and no more."""

_IN_VIEW = 0.5
"""The least share of a shape's outline's area inside where the building stands in the
photo for the shape to be part of it: a neighbour of its colour merely touching that box
(from above, towers overlap in the frame) is not."""


def _share_inside(shape: Shape, box: shapely.Polygon) -> float:
    outline = shapely.MultiPoint(shape.polygon_px).convex_hull
    return float(outline.intersection(box).area / outline.area) if outline.area > 0.0 else 0.0


def _taller_view(
    m: SearchMission, plan: SidePlan, vp: Viewpoint, pose: CameraPose
) -> Viewpoint | None:
    """The viewpoint planned again, from the same direction, for a building taller than the
    top of the view over its near wall (the camera level or looking down); None when no
    viewpoint fits."""
    half_vfov = math.radians(plan.intrinsics.vfov_deg) / 2.0
    up = half_vfov + math.radians(pose.pitch_deg)  # the top of the view above the horizon
    at_least_m = pose.pos_enu_m[2] + vp.distance_m * math.tan(up)
    height_m = _TALLER * max(at_least_m, plan.params.assumed_height_m)
    params = _for_height(m, plan, height_m)
    found = _towards(plan, vp, params)
    far = farther(params, plan.intrinsics)
    if not isinstance(found, Viewpoint) and far is not None:
        farther_off = _towards(plan, vp, far)  # a tower too tall for the distance limit
        if isinstance(farther_off, Viewpoint):
            found = farther_off
    if not isinstance(found, Viewpoint):
        m.event(Level.INFO, f"{vp.name} photo: the building's top is cut; {found.reason}")
        return None
    plan.taller(m, height_m)
    m.event(
        Level.INFO,
        f"{vp.name} photo: the building's top is cut: it is over {at_least_m:.1f} m tall; "
        f"again from {found.distance_m:.1f} m at {found.pos_enu_m[2]:.1f} m up",
    )
    return found


def _looking_down_instead(m: SearchMission, plan: SidePlan, vp: Viewpoint) -> Viewpoint | None:
    """With no room to back away from a level view that cuts the building: from the same
    direction, a camera further off (found with the planner's rules) or one that rises and
    looks down; None when neither fits, or the view already looked down."""
    if vp.pitch_deg < 0.0:
        return None
    found = _towards(plan, vp, plan.params)
    if not isinstance(found, Viewpoint) or not (
        found.pitch_deg < 0.0 or found.distance_m > vp.distance_m
    ):
        return None
    m.event(
        Level.INFO,
        f"{vp.name} photo: planned again from {found.distance_m:.1f} m"
        + (
            f", looking down {-found.pitch_deg:.0f}° from {found.pos_enu_m[2]:.1f} m"
            if found.pitch_deg < 0.0
            else ""
        ),
    )
    return found


def _backed_away(
    m: SearchMission, plan: SidePlan, vp: Viewpoint, step_m: float
) -> Viewpoint | None:
    """``vp`` moved back along its line of sight by ``step_m``; None (and why) when that
    comes within the safety margin of another building."""
    h = math.radians(vp.heading_deg)
    x, y, z = vp.pos_enu_m
    nx, ny = x - math.sin(h) * step_m, y - math.cos(h) * step_m  # it looks along the heading
    room_m = min(
        (point_polygon_distance((nx, ny), o) for o in plan.cautious + plan.unknown),
        default=math.inf,
    )
    if room_m < m.params.viewpoints.safety_margin_m:
        m.event(
            Level.INFO, f"{vp.name} photo: the building touches the border; no room to back away"
        )
        return None
    m.event(
        Level.INFO,
        f"{vp.name} photo: the building touches the image border; backing away {step_m:.1f} m",
    )
    return dataclasses.replace(vp, pos_enu_m=(nx, ny, z), distance_m=vp.distance_m + step_m)
