"""Where to take the front, right and top photos of a building (the paper's
``calcHeadingChangeForImage``).

Sides of a :class:`~uavtool.nav.rect.Rect` with long axis heading θ:

* ``long-a``: the long side whose outward normal points to θ + 90° (for θ in [0, 180)
  that is the southern half of the compass, so the first-choice front camera looks
  north-ish); ``long-b`` is the opposite long side.
* ``short-a``: the short side whose outward normal points to θ; ``short-b`` is opposite.

A camera facing a side stands on that side's outward normal through its midpoint,
``distance_m`` from it, and looks back along the normal. The right photo looks at the
building with heading ``front − 90°``: the camera stands to the building's right as seen
from the front camera. Side photos assume a horizontal camera (gimbal pitch 0).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from uavtool.camera import Intrinsics
from uavtool.nav.errors import NavParamError
from uavtool.nav.geometry import (
    Point,
    as_points,
    point_in_polygon,
    point_polygon_distance,
    triangle_hits_polygon,
)
from uavtool.nav.rect import Rect

_OPPOSITE = {"long-a": "long-b", "long-b": "long-a", "short-a": "short-b", "short-b": "short-a"}


def _stages(heights: Sequence[float] | None, *, roof_line: bool) -> tuple[tuple[bool, bool], ...]:
    """The rounds of cameras turned round or looking down, as ``(rise, roof_only)``: each at
    its lowest; with ``heights``, then rising to see over lower neighbours; with
    ``roof_line`` too, last rising until it sees every roof corner over them, no more. The
    model carves nothing below what a side photo sees of the building
    (`uavtool.vision.model3d.View.foot_hidden`), so a photo of its roof line alone still
    carves its roof's outline; the lower walls it does not show are left standing, bounded
    by the top photo's footprint (a coarser model, never a wrong one)."""
    if heights is None:
        return ((False, False),)
    if not roof_line:
        return ((False, False), (True, False))
    return ((False, False), (True, False), (True, True))


@dataclass(frozen=True, slots=True)
class ViewpointParams:
    """Parameters of :func:`plan_viewpoints`; lengths in metres."""

    margin: float = 0.25
    """Extra field of view around what must be seen, as a fraction: the camera sees
    (1 + margin) times the side's half-length and the needed half-height."""
    camera_alt_m: float = 6.0
    """Altitude of the front and right photos above the ground (z = 0)."""
    assumed_height_m: float = 12.0
    """Tallest building height the vertical field of view must hold, ground to roof."""
    safety_margin_m: float = 4.0
    """Least horizontal clearance between a camera position and any other building."""
    max_distance_m: float = 60.0
    """Farthest a camera may stand from the side it photographs; for a tower no camera
    within it can hold, as far as a level camera must stand to, up to two
    ``distance_step`` beyond it (94 m by default)."""
    distance_step: float = 1.25
    """Factor by which the distance grows on each fallback round."""
    max_pitch_down_deg: float = 40.0
    """How far below the horizon a side camera may look. When no level camera within
    ``max_distance_m`` sees the whole height (a tower), or none has room, the camera rises
    and looks down at the building instead (the model takes side photos up to
    ``model.max_side_tilt_deg``, 45°, off the horizon; 5° are kept for the gimbal's error).
    0: level cameras only."""
    oblique_deg: tuple[float, ...] = (25.0, -25.0, 45.0, -45.0)
    """Last fallbacks, tried in order when no side can be seen square on: the camera turned
    this far around the building from a side's normal (it then sees two walls; the model
    needs its two side photos only ``model.min_view_separation_deg`` apart)."""

    def __post_init__(self) -> None:
        checks = (
            ("margin", self.margin >= 0.0),
            ("camera_alt_m", self.camera_alt_m > 0.0),
            ("assumed_height_m", self.assumed_height_m > 0.0),
            ("safety_margin_m", self.safety_margin_m >= 0.0),
            ("max_distance_m", self.max_distance_m > 0.0),
            ("distance_step", self.distance_step > 1.0),
            ("max_pitch_down_deg", 0.0 <= self.max_pitch_down_deg < 90.0),
        )
        bounds = {
            "margin": "≥ 0",
            "safety_margin_m": "≥ 0",
            "distance_step": "> 1",
            "max_pitch_down_deg": "in [0, 90)",
        }
        for name, ok in checks:
            value = getattr(self, name)
            if not ok or not math.isfinite(value):
                rule = bounds.get(name, "> 0")
                raise NavParamError(f"nav.{name} must be finite and {rule}, got {value}")


@dataclass(frozen=True, slots=True)
class Viewpoint:
    """A camera position (ENU metres) and heading (degrees) for one photo of the building.

    ``side`` is the rectangle side it faces (see the module doc; ``top`` for the top
    photo), ``distance_m`` its distance from that side (the altitude for ``top``),
    ``fallback`` is empty for the first choice, else what changed (``opposite side``,
    ``distance 1.56x``), ``pitch_deg`` the gimbal pitch to use.
    """

    name: str
    pos_enu_m: tuple[float, float, float]
    heading_deg: float
    side: str
    distance_m: float
    fallback: str = ""
    pitch_deg: float = 0.0


@dataclass(frozen=True, slots=True)
class ViewpointFailure:
    """No allowed position for photo ``name``; ``reason`` lists each candidate and its blockers."""

    name: str
    reason: str


def _heading(east: float, north: float) -> float:
    h = math.degrees(math.atan2(east, north)) % 360.0
    return 0.0 if h >= 360.0 else h + 0.0


def _side_geometry(rect: Rect, side: str) -> tuple[Point, Point, Point]:
    """(end 1, end 2, outward unit normal) of a rectangle side."""
    (ax, ay), (nx, ny) = rect.axes()
    cx, cy = rect.center_en
    hl, hw = rect.length_m / 2.0, rect.width_m / 2.0
    if side.startswith("long"):
        s = 1.0 if side == "long-a" else -1.0
        mid = (cx + s * hw * nx, cy + s * hw * ny)
        normal, along, half = (s * nx, s * ny), (ax, ay), hl
    else:
        s = 1.0 if side == "short-a" else -1.0
        mid = (cx + s * hl * ax, cy + s * hl * ay)
        normal, along, half = (s * ax, s * ay), (nx, ny), hw
    end1 = (mid[0] - half * along[0], mid[1] - half * along[1])
    end2 = (mid[0] + half * along[0], mid[1] + half * along[1])
    return end1, end2, normal


def base_distance_m(side_length_m: float, intrinsics: Intrinsics, params: ViewpointParams) -> float:
    """Distance at which a side of this length fills the view with the margin, horizontally
    (half the side) and vertically (ground and ``assumed_height_m`` from ``camera_alt_m``)."""
    tan_h = (intrinsics.width_px / 2.0) / intrinsics.fx_px
    tan_v = (intrinsics.height_px / 2.0) / intrinsics.fy_px
    k = 1.0 + params.margin
    d_h = k * (side_length_m / 2.0) / tan_h
    half_v = max(params.assumed_height_m - params.camera_alt_m, params.camera_alt_m)
    d_v = k * half_v / tan_v
    return max(d_h, d_v, params.safety_margin_m)


def for_building(
    params: ViewpointParams, height_m: float, *, least_alt_m: float
) -> ViewpointParams:
    """``params`` for the side photos of a building ``height_m`` tall: a level camera
    halfway up (never below ``least_alt_m``) whose view holds the whole height."""
    return dataclasses.replace(
        params, assumed_height_m=height_m, camera_alt_m=max(least_alt_m, height_m / 2.0)
    )


def farther(params: ViewpointParams, intrinsics: Intrinsics) -> ViewpointParams | None:
    """``params`` with ``max_distance_m`` as far as a level camera halfway up must stand
    to hold ``assumed_height_m`` in its view, one ``distance_step`` beyond, but no more than
    two steps beyond the limit; None when that is within it already. The last resort for a
    tower no camera within the limit sees."""
    tan_v = (intrinsics.height_px / 2.0) / intrinsics.fy_px
    held_m = (1.0 + params.margin) * (params.assumed_height_m / 2.0) / tan_v
    reach_m = min(held_m, params.max_distance_m * params.distance_step) * params.distance_step
    if reach_m <= params.max_distance_m:
        return None
    return dataclasses.replace(params, max_distance_m=reach_m)


def tilted_cameras(
    distance_m: float, depth_m: float, intrinsics: Intrinsics, params: ViewpointParams
) -> Iterator[tuple[float, float]]:
    """Each ``(altitude, pitch)`` of a camera ``distance_m`` out from a building's near wall
    that looks down at it (pitch ≤ 0) and sees it whole, with the margin, from the ground at
    the near wall up to the top of its far side ``depth_m`` further (``assumed_height_m``
    tall), from ``camera_alt_m`` up in half-metre steps, as long as a pitch within
    ``max_pitch_down_deg`` does it: the lowest first, the higher ones see over more."""
    limit = math.radians(params.max_pitch_down_deg)
    half = math.atan((intrinsics.height_px / 2.0) / intrinsics.fy_px / (1.0 + params.margin))
    tall = params.assumed_height_m
    z = params.camera_alt_m
    while True:
        below_base = math.atan2(z, distance_m)  # the near wall's foot, below the horizon
        top = math.atan2(z - tall, distance_m + depth_m if z > tall else distance_m)
        low = below_base - half  # the least pitch down that holds the foot
        if low > limit:
            return  # higher only looks steeper
        least, most = max(low, 0.0), min(top + half, limit)  # pitches down that hold both
        if least <= most:
            pitch = min(max((below_base + top) / 2.0, least), most)
            yield z, -math.degrees(pitch)
        z += 0.5


def _ids(indices: list[int]) -> str:
    return ("obstacle " if len(indices) == 1 else "obstacles ") + ", ".join(map(str, indices))


def _plan_one(
    name: str,
    rect: Rect,
    first_side: str,
    obstacles: list[list[Point]],
    intrinsics: Intrinsics,
    params: ViewpointParams,
    heights: Sequence[float] | None = None,
    apart_from: tuple[float, float] | None = None,
    *,
    roof_line: bool = False,
) -> Viewpoint | ViewpointFailure:
    """Try the first side, then the opposite one, at growing distances; first clear wins.
    ``apart_from``: (heading, least separation), both degrees: a camera turned round the
    building must look at least that far from the heading, or from its opposite (the
    model needs two distinct directions)."""
    side_len = rect.length_m if first_side.startswith("long") else rect.width_m
    d0 = base_distance_m(side_len, intrinsics, params)
    tried: list[str] = []
    factor, rounds = 1.0, 0
    while d0 * factor <= params.max_distance_m * (1.0 + 1e-12):
        distance = d0 * factor
        for side in (first_side, _OPPOSITE[first_side]):
            end1, end2, normal = _side_geometry(rect, side)
            mid = ((end1[0] + end2[0]) / 2.0, (end1[1] + end2[1]) / 2.0)
            cam = (mid[0] + distance * normal[0], mid[1] + distance * normal[1])
            near = [
                (i, c)
                for i, poly in enumerate(obstacles)
                if (c := point_polygon_distance(cam, poly)) < params.safety_margin_m
            ]
            tri = (cam, end1, end2)
            hidden = [i for i, poly in enumerate(obstacles) if triangle_hits_polygon(tri, poly)]
            if not near and not hidden:
                notes = [] if side == first_side else ["opposite side"]
                if rounds:
                    notes.append(f"distance {factor:.2f}x")
                return Viewpoint(
                    name=name,
                    pos_enu_m=(cam[0], cam[1], params.camera_alt_m),
                    heading_deg=_heading(-normal[0], -normal[1]),
                    side=side,
                    distance_m=distance,
                    fallback=", ".join(notes),
                )
            why = []
            if near:
                clear = ", ".join(f"{i} ({c:.1f} m)" for i, c in near)
                why.append(f"within {params.safety_margin_m:g} m of obstacle {clear}")
            if hidden:
                why.append(f"no line of sight ({_ids(hidden)})")
            tried.append(f"{side} at {distance:.1f} m: " + " and ".join(why))
        rounds += 1
        factor *= params.distance_step
    base_too_far = not tried
    # Every camera turned round or looking down at its lowest first; only then one that
    # rises higher to see over lower neighbours (steeper, it sees less of the walls).
    for rise, roof_only in _stages(heights, roof_line=roof_line):
        how = {"rise": rise, "roof_only": roof_only}
        for offset in params.oblique_deg if not base_too_far else ():  # none fit: say so below
            for side in (first_side, _OPPOSITE[first_side]):
                found = _oblique(
                    name, rect, side, offset, obstacles, intrinsics, params, heights, **how
                )
                if isinstance(found, Viewpoint) and apart_from is not None:
                    apart = _apart_deg(found.heading_deg, apart_from[0])
                    if apart < apart_from[1]:
                        found = f"{side} turned {offset:+g}°: {apart:.0f}° from the other photo's"
                if isinstance(found, Viewpoint):
                    return found
                if not rise:
                    tried.append(found)
        if base_too_far and not rise:
            tried.append(
                f"the base distance {d0:.1f} m exceeds nav.max_distance_m "
                f"{params.max_distance_m:g} m"
            )
        if params.max_pitch_down_deg > 0.0:
            for side in (first_side, _OPPOSITE[first_side]):
                end1, end2, normal = _side_geometry(rect, side)
                depth = rect.width_m if side.startswith("long") else rect.length_m
                mid = ((end1[0] + end2[0]) / 2.0, (end1[1] + end2[1]) / 2.0)
                found = _looking_down(
                    name, side, mid, (end1, end2), normal, depth, side_len,
                    obstacles, intrinsics, params, heights, **how,
                )  # fmt: skip
                if isinstance(found, Viewpoint):
                    return found
                tried.append(found)
    return ViewpointFailure(
        name, f"{name}: " + "; ".join(tried) + f" (tried up to {params.max_distance_m:g} m)"
    )


def _looking_down(
    name: str,
    side: str,
    mid: Point,
    seen: Sequence[Point],
    normal: Point,
    depth_m: float,
    across_m: float,
    obstacles: list[list[Point]],
    intrinsics: Intrinsics,
    params: ViewpointParams,
    heights: Sequence[float] | None = None,
    *,
    rise: bool = False,
    roof_only: bool = False,
) -> Viewpoint | str:
    """A camera out along ``normal`` from ``mid`` (the middle of the near wall) that rises
    and looks down (:func:`tilted_cameras`), at the first distance from the horizontal need
    (``across_m`` wide) or the safety margin, growing, where it keeps the margin and sees
    the points ``seen`` (the wall's ends, or every corner; with ``heights``, from their tops
    down to half their height, or with ``roof_only`` their tops alone) past the obstacles,
    at its lowest altitude (with ``rise``, at the lowest altitude that does); else what
    stopped it. Without ``heights`` the obstacles
    are as tall as any (a level camera's rule); with them (``math.inf``: unknown), the
    camera may see the building's top over a lower obstacle, its lower part hidden
    (:func:`foot_hidden` says so)."""
    tan_h = (intrinsics.width_px / 2.0) / intrinsics.fx_px
    distance = max((1.0 + params.margin) * (across_m / 2.0) / tan_h, params.safety_margin_m)
    why = "too close to look down at steeply enough"
    distances = []
    while distance < params.max_distance_m:
        distances.append(distance)
        distance *= params.distance_step
    for distance in (*distances, params.max_distance_m):  # the farthest allowed last
        cam = (mid[0] + distance * normal[0], mid[1] + distance * normal[1])
        near = any(point_polygon_distance(cam, poly) < params.safety_margin_m for poly in obstacles)
        for z, pitch in tilted_cameras(distance, depth_m, intrinsics, params):
            if near:
                why = "no room"
                break
            if heights is None:
                hidden = any(
                    triangle_hits_polygon((cam, a, b), poly)
                    for poly in obstacles
                    for i, a in enumerate(seen)
                    for b in seen[i + 1 :]
                )
            else:
                # The upper half of the walls, whose silhouette the model is carved from: a
                # photo that sees only their tops shows a sliver. Last, the roof line alone.
                tall = params.assumed_height_m
                hidden = any(
                    _sight_blocked((cam[0], cam[1], z), (q[0], q[1], at), poly, h)
                    for poly, h in zip(obstacles, heights, strict=True)
                    for q in seen
                    for at in ((tall,) if roof_only else (tall, tall / 2.0))
                )
            if not hidden:
                return Viewpoint(
                    name=name,
                    pos_enu_m=(cam[0], cam[1], z),
                    heading_deg=_heading(-normal[0], -normal[1]),
                    side=side,
                    distance_m=distance,
                    fallback=f"{side} side, "
                    + (
                        f"looking down {-pitch:.0f}° from {z:.1f} m"
                        if pitch < 0.0
                        else f"level from {z:.1f} m, {distance:.1f} m off"
                    )
                    + (", over its neighbours to its roof line" if roof_only else ""),
                    pitch_deg=pitch,
                )
            why = "no line of sight"
            if heights is None or not rise:
                break  # the lowest only (obstacles as tall as any: none sees over them)
    over = ", over its neighbours to its roof line" if roof_only else ""
    return f"{side} looking down{', rising' if rise else ''}{over}: {why}"


def _sight_blocked(
    eye: tuple[float, float, float],
    point: tuple[float, float, float],
    footprint: Sequence[Point],
    height_m: float,
) -> bool:
    """Whether the straight line from ``eye`` to ``point`` passes through a building of
    ``footprint`` standing ``height_m`` tall (``math.inf``: of unknown height)."""
    (ex, ey, ez), (px, py, pz) = eye, point
    xs = [x for x, _ in footprint]
    ys = [y for _, y in footprint]
    if (
        max(ex, px) < min(xs)
        or min(ex, px) > max(xs)
        or max(ey, py) < min(ys)
        or min(ey, py) > max(ys)
    ):
        return False  # the line's box misses the footprint's: neither end in it, no crossing
    if point_in_polygon((px, py), footprint):
        return False  # the point stands in it (a building touching the target)
    dx, dy = px - ex, py - ey
    ts = [0.0] if point_in_polygon((ex, ey), footprint) else []
    n = len(footprint)
    for i in range(n):
        (ax, ay), (bx, by) = footprint[i], footprint[(i + 1) % n]
        ux, uy = bx - ax, by - ay
        den = dx * uy - dy * ux
        if den == 0.0:
            continue  # parallel: the line meets the building at another edge too
        t = ((ax - ex) * uy - (ay - ey) * ux) / den
        u = ((ax - ex) * dy - (ay - ey) * dx) / den
        if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
            ts.append(t)
    # Inside the footprint the line is lowest where it leaves it (it descends to the point,
    # or rises): at one of these crossings.
    return any(ez + (pz - ez) * t < height_m for t in ts)


def foot_hidden(
    eye: tuple[float, float, float],
    corners: Sequence[Point],
    obstacles: Sequence[Sequence[Point]],
    heights: Sequence[float],
) -> bool:
    """Whether a building stands between ``eye`` and the foot of any of ``corners`` (its
    footprint's, on the ground): the photo then shows the building's top over it, not its
    walls down to the ground."""
    return any(
        _sight_blocked(eye, (x, y, 0.0), poly, h)
        for poly, h in zip(obstacles, heights, strict=True)
        for x, y in corners
    )


def _oblique(
    name: str,
    rect: Rect,
    side: str,
    offset_deg: float,
    obstacles: list[list[Point]],
    intrinsics: Intrinsics,
    params: ViewpointParams,
    heights: Sequence[float] | None = None,
    *,
    rise: bool = False,
    roof_only: bool = False,
) -> Viewpoint | str:
    """A camera on ``side``'s normal turned ``offset_deg`` around the building's centre, at
    the first distance (growing as square-on ones do) where it keeps the safety margin and
    sees every corner past the obstacles (level, or rising to look down over obstacles of
    known ``heights``); else what blocked it."""
    _, _, normal = _side_geometry(rect, side)
    a = math.radians(offset_deg)
    u = (
        normal[0] * math.cos(a) - normal[1] * math.sin(a),
        normal[0] * math.sin(a) + normal[1] * math.cos(a),
    )
    found = _from_direction(
        name,
        rect,
        u,
        side,
        f"turned {offset_deg:+g}° from the {side} side",
        obstacles,
        intrinsics,
        params,
        heights,
        rise=rise,
        roof_only=roof_only,
    )
    if isinstance(found, Viewpoint):
        return found
    return f"{side} turned {offset_deg:+g}°: {found}"


def _from_direction(
    name: str,
    rect: Rect,
    u: Point,
    side: str,
    label: str,
    obstacles: list[list[Point]],
    intrinsics: Intrinsics,
    params: ViewpointParams,
    heights: Sequence[float] | None = None,
    *,
    rise: bool = False,
    roof_only: bool = False,
) -> Viewpoint | str:
    """A camera out from the rectangle's centre along the unit vector ``u``, looking back at
    it, at the first distance (growing as square-on ones do) where it keeps the safety
    margin and sees every corner past the obstacles; else what blocked it."""
    cx, cy = rect.center_en
    corners = rect.corners()
    depth = max((x - cx) * u[0] + (y - cy) * u[1] for x, y in corners)
    across = [(x - cx) * -u[1] + (y - cy) * u[0] for x, y in corners]
    d0 = base_distance_m(max(across) - min(across), intrinsics, params)
    factor = 1.0
    blocked = ""
    while d0 * factor <= params.max_distance_m * (1.0 + 1e-12):
        distance = d0 * factor
        cam = (cx + (depth + distance) * u[0], cy + (depth + distance) * u[1])
        near = [
            i
            for i, poly in enumerate(obstacles)
            if point_polygon_distance(cam, poly) < params.safety_margin_m
        ]
        hidden = [
            i
            for i, poly in enumerate(obstacles)
            if any(
                triangle_hits_polygon((cam, corners[j], corners[k]), poly)
                for j in range(4)
                for k in range(j + 1, 4)
            )
        ]
        if not near and not hidden:
            return Viewpoint(
                name=name,
                pos_enu_m=(cam[0], cam[1], params.camera_alt_m),
                heading_deg=_heading(-u[0], -u[1]),
                side=side,
                distance_m=distance,
                fallback=label + (f", distance {factor:.2f}x" if factor > 1.0 else ""),
            )
        blocked = "no line of sight" if hidden else "no room"
        factor *= params.distance_step
    if not params.max_pitch_down_deg > 0.0:
        return blocked or "beyond nav.max_distance_m"
    # No level camera: one that rises and looks down, facing the corners' span.
    mid = (cx + depth * u[0], cy + depth * u[1])  # the middle of the near side's span
    down = _looking_down(
        name,
        side,
        mid,
        corners,
        u,
        2.0 * depth,
        max(across) - min(across),
        obstacles,
        intrinsics,
        params,
        heights,
        rise=rise,
        roof_only=roof_only,
    )
    if isinstance(down, Viewpoint):
        return dataclasses.replace(down, fallback=f"{label}, {down.fallback}")
    return blocked or "beyond nav.max_distance_m"


def _apart_deg(a_deg: float, b_deg: float) -> float:
    """How far apart two viewing directions are, a direction and its opposite as one."""
    d = abs((a_deg - b_deg + 180.0) % 360.0 - 180.0)
    return min(d, 180.0 - d)


def plan_viewpoints(
    target: Rect,
    obstacles: Sequence[Sequence[tuple[float, float]]] | Sequence[Any],
    intrinsics: Intrinsics,
    params: ViewpointParams | None = None,
    heights: Sequence[float] | None = None,
    min_apart_deg: float = 0.0,
    *,
    roof_line: bool = False,
) -> tuple[Viewpoint | ViewpointFailure, Viewpoint | ViewpointFailure]:
    """The front and right viewpoints of ``target``, clear of ``obstacles``.

    obstacles : other buildings' footprints, each an (n, 2) ENU ring.
    Front faces ``long-a`` first, right the short side at heading front − 90°; each
    candidate must keep ``safety_margin_m`` from every obstacle and see its whole side
    past them (obstacles are treated as infinitely tall). Fallbacks: the opposite side,
    then both sides at distances grown by ``distance_step`` up to ``max_distance_m``, then
    cameras turned round the building, last cameras that rise and look down at it. With
    ``heights`` (each obstacle's, ``math.inf`` where unknown) a camera looking down may see
    the building's top over lower obstacles: the upper half of its walls; with
    ``roof_line``, last its roof line alone (`_stages`).
    When the front has no position, the right photo is planned against the first-choice
    front heading. A right camera turned round the building looks at least
    ``min_apart_deg`` away from the front camera's direction (the model's
    ``min_view_separation_deg``).
    """
    params = params or ViewpointParams()
    polys = [as_points(p, what=f"obstacles[{i}]") for i, p in enumerate(obstacles)]
    front = _plan_one(
        "front", target, "long-a", polys, intrinsics, params, heights, roof_line=roof_line
    )
    front_side = front.side if isinstance(front, Viewpoint) else "long-a"
    # long-a looks along θ − 90, so its right camera looks along θ − 180: it faces short-a
    # (outward normal θ); symmetrically long-b → short-b.
    right_side = "short-a" if front_side == "long-a" else "short-b"
    apart = (front.heading_deg, min_apart_deg) if isinstance(front, Viewpoint) else None
    right = _plan_one(
        "right", target, right_side, polys, intrinsics, params, heights, apart, roof_line=roof_line
    )
    return front, right


def plan_towards(
    name: str,
    target: Rect,
    direction_en: tuple[float, float],
    obstacles: Sequence[Sequence[tuple[float, float]]] | Sequence[Any],
    intrinsics: Intrinsics,
    params: ViewpointParams,
    label: str,
    heights: Sequence[float] | None = None,
) -> Viewpoint | ViewpointFailure:
    """A camera out from ``target``'s centre along ``direction_en`` (east, north; any
    length), looking back at it, at the first distance where it keeps the safety margin and
    sees every corner past the obstacles (``label`` becomes its ``fallback`` note); with
    ``heights``, last one that rises higher to see over lower ones."""
    n = math.hypot(*direction_en)
    if not n > 0.0:
        return ViewpointFailure(name, f"{name}: no direction to look from")
    polys = [as_points(p, what=f"obstacles[{i}]") for i, p in enumerate(obstacles)]
    u = (direction_en[0] / n, direction_en[1] / n)
    found: Viewpoint | str = ""
    for rise, roof_only in _stages(heights, roof_line=False):
        how = {"rise": rise, "roof_only": roof_only}
        found = _from_direction(
            name, target, u, name, label, polys, intrinsics, params, heights, **how
        )
        if isinstance(found, Viewpoint):
            return found
    return ViewpointFailure(name, f"{name}: {found}")


def plan_diagonal(
    target: Rect,
    front_en: Sequence[float],
    right_en: Sequence[float],
    obstacles: Sequence[Sequence[tuple[float, float]]] | Sequence[Any],
    intrinsics: Intrinsics,
    params: ViewpointParams | None = None,
) -> Viewpoint | ViewpointFailure:
    """A third side photo, looking at ``target`` across a corner: from halfway between the
    directions of the front and right cameras (where they stood, east and north), else from
    behind both, else from the two other diagonals. It sees under a building along lines
    the square-on photos cannot (the corner of an L-shaped arch), so its silhouette carves
    what theirs leave standing."""
    params = params or ViewpointParams()
    polys = [as_points(p, what=f"obstacles[{i}]") for i, p in enumerate(obstacles)]
    cx, cy = target.center_en
    units = []
    for camera in (front_en, right_en):
        ex, ey = camera[0] - cx, camera[1] - cy
        n = math.hypot(ex, ey) or 1.0
        units.append((ex / n, ey / n))
    (fx, fy), (rx, ry) = units
    tried = []
    for label, (ux, uy) in (
        ("between the front and right cameras", (fx + rx, fy + ry)),
        ("behind the front and right cameras", (-fx - rx, -fy - ry)),
        ("between the front camera and the right one's opposite", (fx - rx, fy - ry)),
        ("between the right camera and the front one's opposite", (rx - fx, ry - fy)),
    ):
        n = math.hypot(ux, uy)
        if n < 1e-9:  # front and right from the same direction: no diagonal between them
            continue
        found = _from_direction(
            "diagonal", target, (ux / n, uy / n), "diagonal", label, polys, intrinsics, params
        )
        if isinstance(found, Viewpoint):
            return found
        tried.append(f"{label}: {found}")
    return ViewpointFailure("diagonal", "diagonal: " + "; ".join(tried))


def top_viewpoint(target: Rect, front_heading_deg: float, *, alt_m: float) -> Viewpoint:
    """The nadir photo above the rectangle's centre, camera heading = the front photo's."""
    cx, cy = target.center_en
    return Viewpoint(
        name="top",
        pos_enu_m=(cx, cy, float(alt_m)),
        heading_deg=float(front_heading_deg) % 360.0,
        side="top",
        distance_m=float(alt_m),
        fallback="",
        pitch_deg=-90.0,
    )
