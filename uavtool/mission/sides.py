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

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level
from uavtool.mission.search import photo_shapes
from uavtool.nav import Rect, Viewpoint, ViewpointFailure, ViewpointParams, plan_towards
from uavtool.nav.geometry import point_polygon_distance
from uavtool.nav.viewpoints import foot_hidden
from uavtool.vision import Shape
from uavtool.vision.model3d import View, same_colour
from uavtool.vision.shapes import cut_edges

if TYPE_CHECKING:
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

    def sight(self) -> tuple[list[Ring], list[float] | None]:
        """The footprints a camera must see past, with their heights (None: unknown)."""
        footprints = self.obstacles + self.unknown
        if not self.heights:
            return footprints, None
        return footprints, self.heights + [math.inf] * len(self.unknown)

    def taller(self, m: SearchMission, height_m: float) -> None:
        """Plan from now on for a building ``height_m`` tall."""
        self.params = _for_height(m, self.params, height_m)
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


def _for_height(m: SearchMission, params: ViewpointParams, height_m: float) -> ViewpointParams:
    return dataclasses.replace(
        params,
        assumed_height_m=height_m,
        camera_alt_m=max(m.params.viewpoints.camera_alt_m, height_m / 2.0),
    )


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
) -> Wait[tuple[View, Viewpoint]]:
    """A side photo from ``vp`` — planned again first if the building proved taller since,
    unless ``fresh`` (planned with the plan's parameters as they are) — and the viewpoint it
    was finally taken from (see the module doc for the photos taken again)."""
    p = m.params.mission
    if not fresh:
        vp = plan.again(m, vp)
    x, y, z = vp.pos_enu_m
    step_m = vp.distance_m * 0.5  # backing away: half the planned distance at a time
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
        vp = moved
        x, y, z = vp.pos_enu_m
        # Up, across and down again: the way may pass a building the plan did not know.
        yield from m.move(
            (photo.pose.pos_enu_m[0], photo.pose.pos_enu_m[1], plan.transit_m), None, "climb"
        )
        yield from m.travel((x, y, z), vp.heading_deg, plan.transit_m, f"{vp.name} viewpoint")
    yield from m.move((x, y, plan.transit_m), vp.heading_deg, f"climb from the {vp.name} viewpoint")
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


def _in_line(shapes: tuple[Shape, ...], rect: Rect, photo: Photo) -> tuple[Shape, ...]:
    """The shapes across the image columns where the building stands (its footprint's corners
    projected, a tenth of that span to spare): a building of a close colour beside or far
    behind it is not part of its silhouette. All of them when none is there."""
    corners = np.array([(x, y, photo.pose.pos_enu_m[2]) for x, y in rect.corners()])
    uvz = project(corners, photo.pose, photo.intrinsics)
    if np.any(uvz[:, 2] <= 0.0):
        return shapes  # the camera stands over the footprint: no columns to tell by
    lo, hi = float(uvz[:, 0].min()), float(uvz[:, 0].max())
    spare = 0.1 * (hi - lo)
    kept = tuple(
        s
        for s in shapes
        if s.polygon_px[:, 0].max() >= lo - spare and s.polygon_px[:, 0].min() <= hi + spare
    )
    return kept or shapes


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
    found = _towards(plan, vp, _for_height(m, plan.params, height_m))
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
