"""The photos for the model and the model: the top photo from an altitude that fits the
building, the front and right photos from planned viewpoints (:mod:`uavtool.mission.sides`),
a diagonal photo when the model is open underneath, and the model."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

from uavtool.mission.analysis import aimed_shape, judge, roof_between
from uavtool.mission.looks import Found, photo_shapes
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import DiagonalView, Level, ModelBuilt, Status, Viewpoints
from uavtool.mission.sides import SidePlan, side_view
from uavtool.mission.survey import (
    Survey,
    beyond_the_frame,
    building_top_m,
    obstacles_around,
    remeasured_obstacles,
    same_building,
)
from uavtool.nav import (
    Rect,
    Viewpoint,
    ViewpointFailure,
    ViewpointParams,
    ground_polygon,
    min_area_rect,
    plan_diagonal,
    plan_viewpoints,
    top_viewpoint,
)
from uavtool.nav.geometry import point_polygon_distance, polygons_overlap
from uavtool.nav.heights import fit_altitude_m
from uavtool.nav.viewpoints import farther, for_building
from uavtool.vision import Shape
from uavtool.vision.errors import VisionError
from uavtool.vision.model3d import (
    Model,
    View,
    build_model,
    open_beneath,
)

if TYPE_CHECKING:
    from uavtool.camera import Intrinsics
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


def still_the_target(
    m: SearchMission, found: Found, photo: Photo, shapes: tuple[Shape, ...]
) -> None:
    """The top photo is the closest look at the match and draws it larger than the look
    did. Where its corners score at the threshold again (and its hue is the target's), the
    building must still be more like the target than like the target's mirror image, and
    show as many courtyards as the target picture: a near shape the look drew too small to
    tell apart may fail either here. The mission then ends NO_MATCH rather than model
    another building. Its outline is not judged again from here: a building at several
    heights seen this close lies off its own outline from afar by its tiers' perspective
    (paper's red, under a low sun, 4.5 % off), so the event only reports it. (Corners under
    the threshold prove nothing either: a tall building's walls seen close change them.)"""
    j = judge(
        m.params,
        m.target,
        shapes,
        photo.intrinsics,
        found.shape.colour_rgb,
        target_stepped=m.target_stepped,
    )
    if j.candidate < 0 or not j.judgeable or not j.same_hue:
        return
    if j.score < m.params.recognize.threshold:
        return
    shape = shapes[j.candidate]
    if not j.not_mirror:
        why = f"as much like the target's mirror image ({j.mirror_score:.3f})"
    elif len(shape.holes_px) != len(m.target.holes_px):
        why = (
            f"{len(shape.holes_px)} courtyard(s) where the target picture shows "
            f"{len(m.target.holes_px)}"
        )
    else:
        if j.outline_tolerance > 0.0:
            m.event(
                Level.INFO,
                f"top photo: outline {j.outline_gap * 100:.1f} % of its size off the target's "
                f"(the photos' accuracy {j.outline_tolerance * 100:.1f} %; not judged this close)",
            )
        return
    m.matched_poi, m.match_score = -1, 0.0
    raise m.end(
        Status.NO_MATCH,
        f"point of interest {found.poi.index} matched, but the top photo, closer, shows it "
        f"{why}: not the target",
    )


def _roof_line(
    rect: Rect,
    obstacles: list[Any],
    k: Intrinsics,
    params: ViewpointParams,
    heights: list[float],
    apart: float,
    planned: tuple[Viewpoint | ViewpointFailure, Viewpoint | ViewpointFailure],
) -> tuple[Viewpoint | ViewpointFailure, Viewpoint | ViewpointFailure]:
    """``planned`` (by `plan_viewpoints` on these arguments), or where a side has no
    viewpoint that sees the upper half of the walls over the neighbours, planned again
    with one that sees the roof line over them as the last round (``roof_line``): a coarser
    model than none. A side planned is planned the same again."""
    if not any(isinstance(v, ViewpointFailure) for v in planned):
        return planned
    return plan_viewpoints(rect, obstacles, k, params, heights, apart, roof_line=True)


def photograph_and_model(
    m: SearchMission, found: Found, seen: Survey, transit_m: float
) -> Wait[None]:
    """Top, front and right photos from planned viewpoints, then the model. The side photos
    are taken only once the top photo shows the whole building."""
    p = m.params.mission
    # The building's highest part: one tier of a stepped tower may have been found apart
    # from the others, each measured on its own.
    top_m = building_top_m(seen, same_building(m, seen, found.poi.shape_index))
    roof = max(found.roof_m, top_m)
    k = found.photo.intrinsics
    vp_params = _side_params(m, roof)
    footprint = ground_polygon(
        found.shape.polygon_px,
        found.photo.pose,
        k,
        plane_z_m=min(found.roof_m, _below(found.photo)),
    )
    rect = min_area_rect(footprint)
    around = obstacles_around(m, seen, found.poi.shape_index)
    others = [f for f, _ in around]
    apart = m.params.model.min_view_separation_deg
    front, right = plan_viewpoints(rect, others, k, vp_params, [h for _, h in around], apart)
    front_heading = (
        front.heading_deg if isinstance(front, Viewpoint) else (rect.long_axis_deg + 90.0) % 360.0
    )
    extent = math.hypot(rect.length_m, rect.width_m)
    alt = max(
        fit_altitude_m(roof_m=roof, extent_m=extent, intrinsics=k, fill=p.top_fill),
        roof + p.min_above_roof_m,
    )
    for attempt in range(1, p.max_looks + 1):
        top = top_viewpoint(rect, front_heading, alt_m=alt)
        # never below a known roof within the margin, nor near one of unknown height
        floor_m = m.floor_at(top.pos_enu_m[0], top.pos_enu_m[1])
        if floor_m > alt:
            alt = floor_m
            top = top_viewpoint(rect, front_heading, alt_m=alt)
        yield from m.travel(top.pos_enu_m, top.heading_deg, transit_m, "top viewpoint")
        top_photo = yield from m.photo("top" if attempt == 1 else f"top-{attempt}", -90.0)
        top_shapes = photo_shapes(m, top_photo)
        # the building of the match's colour the photo is centred on (a lawn or a field of
        # another hue around it, in the middle of the photo too, is not it)
        obj = aimed_shape(m.params, top_shapes, top_photo.intrinsics, found.shape.colour_rgb)
        if obj is None:
            m.no_model = "the top photo shows no building"
            return
        if not obj.cut_by_border:
            break
        m.event(
            Level.INFO,
            f"top photo from {alt:.1f} m: the building touches the image border; "
            + ("again from higher" if attempt < p.max_looks else "giving up"),
        )
        alt = roof + (alt - roof) * 1.5
    else:
        m.no_model = f"the top photo never showed the whole building ({p.max_looks} tries)"
        return
    still_the_target(m, found, top_photo, top_shapes)
    if not found.roof_measured:
        # The look and the top photo see the building whole from two places: its height,
        # which neither the overview nor a photo from another altitude could tell (a tower
        # cut by the overview's border, looked at from the ceiling), plans the side photos.
        measured = roof_between(found.shape, found.photo, obj, top_photo)
        if measured is not None and measured < _below(top_photo):
            m.event(
                Level.INFO,
                f"the look and the top photo measure the target's roof {measured:.1f} m above home",
            )
            found = dataclasses.replace(found, roof_m=measured, roof_measured=True)
            roof = max(measured, top_m)
            vp_params = _side_params(m, roof)
    # The top photo, low over the target, measures the neighbours the overview could not.
    remeasured = remeasured_obstacles(m, seen, found.poi.shape_index, top_photo, top_shapes)
    obstacles = [f for f, _ in remeasured]
    heights = [h for _, h in remeasured]
    # The top photo is centred on the building: plan the side photos from its footprint.
    footprint = ground_polygon(
        obj.polygon_px, top_photo.pose, top_photo.intrinsics, plane_z_m=found.roof_m
    )
    rect = min_area_rect(footprint)
    front, right = plan_viewpoints(rect, obstacles, top_photo.intrinsics, vp_params, heights, apart)
    standing = m.standing_vehicles()
    if _among(standing, (front, right)):
        # a viewpoint where another vehicle stands (a fleet's, landed at its home): the
        # airspace would never grant it; planned again with them as obstacles
        m.event(Level.INFO, "a side viewpoint lies where another vehicle stands: planned again")
        obstacles = obstacles + [f for f, _ in standing]
        heights = heights + [h for _, h in standing]
        front, right = plan_viewpoints(
            rect, obstacles, top_photo.intrinsics, vp_params, heights, apart
        )
    far = farther(vp_params, top_photo.intrinsics)
    failed = sum(isinstance(v, ViewpointFailure) for v in (front, right))
    if far is not None and failed:
        # a tower too tall for any camera within the distance limit: from farther off
        front_far, right_far = plan_viewpoints(
            rect, obstacles, top_photo.intrinsics, far, heights, apart
        )
        if sum(isinstance(v, ViewpointFailure) for v in (front_far, right_far)) < failed:
            front, right, vp_params = front_far, right_far, far
    front, right = _roof_line(
        rect, obstacles, top_photo.intrinsics, vp_params, heights, apart, (front, right)
    )
    m.viewpoints = Viewpoints(footprint, top, front, right)
    m.emit(m.viewpoints)

    # Backing away must keep clear of the survey's cautious footprints too: a neighbour
    # measured again may have been paired with the wrong roof.
    sides = SidePlan(
        rect,
        obstacles,
        obstacles + others,
        beyond_the_frame(seen),
        k,
        vp_params,
        transit_m,
        heights=heights,
        height_known=found.roof_measured,
    )
    views: dict[str, View] = {}
    taken: dict[str, Viewpoint] = {}
    planned = {"front": front, "right": right}
    # Another vehicle (a fleet's) may take one side photo while this one takes the other.
    handed = m.side_elsewhere(
        sides, tuple(v for v in (front, right) if isinstance(v, Viewpoint)), obj.colour_rgb
    )
    # its own photo first, the one handed over last
    names = (
        ("right", "front") if handed is not None and handed.name == "front" else ("front", "right")
    )
    for name in names:
        if handed is not None and name == handed.name:
            got = yield from handed.collect()
            if got is not None:
                views[name], taken[name] = got
                continue
            m.event(Level.INFO, f"{name} viewpoint: the other vehicle brought no photo: taking it")
            handed = None
        for _ in range(p.max_looks):
            vp = planned[name]
            if isinstance(vp, ViewpointFailure):
                m.event(Level.WARNING, f"{vp.name} viewpoint impossible: {vp.reason}")
                break
            if vp.fallback:
                m.event(Level.INFO, f"{vp.name} viewpoint: {vp.fallback}")
            # With the other photo handed over, this one waits where it took its own: the
            # model is built there (any way on, home or the diagonal photo's, climbs first).
            got = yield from side_view(m, sides, vp, obj.colour_rgb, climb=handed is None)
            if got is not None and got[0].shapes:
                views[name], taken[name] = got
                break
            if got is not None:
                # Nothing of its colour where the building stands in the photo: something no
                # photo from above told stands between (a building of unknown height may
                # stand anywhere in its region, the target's too). Planned again from
                # elsewhere: no sight line along this one.
                below = [_sight_line(vp, rect, m.params.viewpoints.safety_margin_m)]
                m.event(
                    Level.WARNING,
                    f"{name} photo: the building does not show where it stands; something "
                    "stands between",
                )
                why = "with no sight line along that one"
            else:
                # the look down from the ceiling showed a building near it: planned again
                # around what it showed (the right photo still apart from the front's heading)
                below = _seen_below(m, sides)
                why = f"around the {len(below)} building(s) the look down showed"
            if not below:
                break
            sides.obstacles += below
            sides.cautious += below
            if sides.heights:
                sides.heights += [math.inf] * len(below)
            again = plan_viewpoints(
                rect, sides.obstacles, top_photo.intrinsics, sides.params, sides.heights, apart
            )
            again = _roof_line(
                rect, sides.obstacles, top_photo.intrinsics, sides.params, sides.heights, apart,
                again,
            )  # fmt: skip
            planned = {"front": taken.get("front", again[0]), "right": again[1]}
            m.event(
                Level.INFO,
                f"{name} viewpoint: planned again {why}",
            )

    missing = [name for name in ("front", "right") if name not in views]
    if missing:
        m.no_model = f"no {' or '.join(missing)} photo"
        m.event(Level.WARNING, f"model not built: {m.no_model}")
        return
    top_view = View((obj,), top_photo.pose, top_photo.intrinsics)
    try:
        model = build_model(top_view, views["front"], views["right"], m.params.model)
    except VisionError as exc:
        m.no_model = str(exc)
        m.event(Level.ERROR, f"model not built: {exc}")
        return
    model = yield from _diagonal(
        m,
        model,
        (top_view, views["front"], views["right"]),
        sides,
        (taken["front"].pos_enu_m, taken["right"].pos_enu_m),
        obj.colour_rgb,
    )
    if open_beneath(model, ground_z_m=m.params.model.ground_z_m) >= _STANDS_ON_NOTHING:
        # A building stands on something: a model with nothing at all near the ground is
        # what side photos that never saw its foot carved, not the building.
        m.no_model = "the side photos never saw the building's foot: the model stands on nothing"
        m.event(Level.WARNING, f"model not built: {m.no_model}")
        return
    m.model = ModelBuilt(
        tuple(tuple(v) for v in model.vertices_m.tolist()),
        tuple(tuple(f) for f in model.faces.tolist()),
        model.height_m,
        model.volume_m3,
    )
    m.emit(m.model)
    m.model_built = True
    # The model measures the target's height: the way home crosses over it by the margin.
    clear_m = model.height_m + m.params.viewpoints.safety_margin_m + p.arrive_radius_m
    m.transit_m = max(m.transit_m or 0.0, clear_m)
    m.roofs = (*m.roofs, (tuple(footprint), model.height_m))
    m.event(
        Level.INFO,
        f"model built: height {model.height_m:.2f} m, volume {model.volume_m3:.1f} m³",
    )


def _seen_below(m: SearchMission, sides: SidePlan) -> list[tuple[tuple[float, float], ...]]:
    """What the last look down from the ceiling showed standing (each region carried to the
    ground, holding its footprint) that the side photos are not yet planned around; never
    the target itself."""
    if not m.peeks:
        return []
    target = list(sides.rect.corners())
    return [
        ring
        for ring in m.peeks[-1].buildings
        if len(ring) >= 3 and not polygons_overlap(ring, target) and ring not in sides.obstacles
    ]


def _sight_line(vp: Viewpoint, rect: Rect, short_m: float) -> tuple[tuple[float, float], ...]:
    """The ground under the line of sight from viewpoint ``vp`` to the building of ``rect``,
    a metre wide, stopping ``short_m`` before it: where a photo showed something stand
    between, an obstacle of unknown height that blocks every sight line across it."""
    x, y, _ = vp.pos_enu_m
    cx, cy = rect.center_en
    n = math.hypot(cx - x, cy - y)
    ux, uy = (cx - x) / n, (cy - y) / n
    length = max(point_polygon_distance((x, y), rect.corners()) - short_m, _HALF_WIDTH_M)
    ex, ey = x + ux * length, y + uy * length
    wx, wy = -uy * _HALF_WIDTH_M, ux * _HALF_WIDTH_M
    return ((x + wx, y + wy), (ex + wx, ey + wy), (ex - wx, ey - wy), (x - wx, y - wy))


_HALF_WIDTH_M = 0.5
"""Half the width of a blocked sight line (`_sight_line`): it stands in for no known
building, only for the line itself; the safety margin keeps cameras off it."""


def _side_params(m: SearchMission, roof_m: float) -> ViewpointParams:
    """Side photos of a building ``roof_m`` tall (at least as tall as the viewpoints'
    ``assumed_height_m``): a horizontal camera halfway up, its view holding the whole
    height."""
    p = m.params.viewpoints
    return for_building(p, max(p.assumed_height_m, roof_m), least_alt_m=p.camera_alt_m)


_STANDS_ON_NOTHING = 0.99
"""The share of a model's footprint open beneath it from which it is no building's model."""


def _diagonal(
    m: SearchMission,
    model: Model,
    views: tuple[View, View, View],
    sides: SidePlan,
    cameras: tuple[tuple[float, float, float], tuple[float, float, float]],
    colour_rgb: tuple[int, int, int],
) -> Wait[Model]:
    """``model`` (from the top, front and right ``views``), carved by a photo from a diagonal
    when the side photos saw through under the building: two square-on views cannot see
    through every part of an opening (the corner of an L-shaped arch stands on no pillar,
    yet hides behind one from both sides). ``cameras``: the viewpoints the front and right
    photos were taken from."""
    share = open_beneath(model, ground_z_m=m.params.model.ground_z_m)
    if share < m.params.mission.diagonal_open_beneath:
        return model
    diagonal = plan_diagonal(
        sides.rect,
        cameras[0],
        cameras[1],
        sides.obstacles + sides.unknown,
        sides.intrinsics,
        sides.params,
    )
    m.emit(DiagonalView(share, diagonal))
    if isinstance(diagonal, ViewpointFailure):
        m.event(Level.INFO, f"the model is open under {share:.0%} of it; {diagonal.reason}")
        return model
    m.event(
        Level.INFO,
        f"the model is open under {share:.0%} of it: a diagonal photo, {diagonal.fallback}",
    )
    got = yield from side_view(m, sides, diagonal, colour_rgb, fresh=True)
    if got is None:
        return model
    view, _ = got
    try:
        return build_model(*views, m.params.model, more=(view,))
    except VisionError as exc:
        m.event(Level.WARNING, f"diagonal photo not used: {exc}")
        return model


def _below(photo: Photo) -> float:
    """Just below the camera: the highest plane a nadir photo's pixels can be put on."""
    return photo.pose.pos_enu_m[2] - 0.5


def _among(
    standing: list[tuple[tuple[tuple[float, float], ...], float]],
    viewpoints: tuple[Viewpoint | ViewpointFailure, ...],
) -> bool:
    """Whether a planned viewpoint lies inside the footprint of a standing vehicle (a square),
    below its height."""
    for footprint, height_m in standing:
        (e0, n0), (e1, n1) = footprint[0], footprint[2]  # the square's opposite corners
        for vp in viewpoints:
            if isinstance(vp, Viewpoint):
                e, n, up = vp.pos_enu_m
                if e0 <= e <= e1 and n0 <= n <= n1 and up < height_m:
                    return True
    return False
