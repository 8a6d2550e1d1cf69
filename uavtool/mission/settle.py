"""Which building that matched is the target. A rival is told apart by a closer look (its
outline against the target's) or, when the target picture shows a higher part's walls
inside its roof, by a photo taken as the picture was (a flat near shape shows none). A lone
match and a rival left in doubt are checked the same way. When nothing tells two apart, the
mission ends NO_MATCH naming both: naming one would be a guess."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import shapely

from uavtool.mission.analysis import Judgement, shows_higher_part
from uavtool.mission.looks import (
    Found,
    Look,
    farthest_pair,
    found,
    less_accuracy,
    of_target_hue,
    on_roof,
    photo_shapes,
    point_on_roof,
    resolving_altitude_m,
    shift,
    take_look,
    whole_altitude_m,
)
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest, Status
from uavtool.nav import NavError, ground_point, ground_polygon
from uavtool.nav.heights import fit_altitude_m, nadir_px
from uavtool.vision import Shape, best_match
from uavtool.vision.vectorize import enclosed_openings
from uavtool.vision.verify import carried_point, outline_accuracy_px

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


def settle(m: SearchMission, best: Found, matches: list[Found]) -> Wait[Found]:
    """The target among the buildings that matched: ``best`` when no other did, or when a
    closer look at each tells them apart. Two buildings both match when each lies on the
    target's outline as closely as its photos can tell (or the target picture, showing parts
    at several heights, was not compared), and both show as many courtyards as the target
    picture: a building *almost* the target (a corner cut, an arm shorter) scores like it by
    its corners, sometimes higher. A closer look shrinks its photo's part of the tolerance:
    each is looked at again from where it fills ``mission.top_fill`` of the photo (its roof
    measured, so the descent is safe), and one whose outline then lies off the target's is
    out. When the target picture shows a higher part's walls, what tells them apart (and
    tells a lone match from a flat near shape) is instead whether their roofs show one
    (`_by_tiers`). When more than one is left, the mission ends NO_MATCH naming two of them:
    naming one would be a guess."""
    left = [best, *_rivals_of(m, best, matches)]
    if m.target_tiers and not best.outline_compared:
        left = yield from _by_tiers(m, left)
    if len(left) == 1:
        return left[0]
    if all(f.outline_compared for f in left):
        closer = []
        for f in left:
            j = yield from _look_closer(m, f, left)
            if j is None or j.matched:
                closer.append(f)
            else:
                m.event(
                    Level.INFO,
                    f"point of interest {f.poi.index}: from closer, its outline lies off the "
                    "target's: not the target",
                )
        left = closer
    if len(left) == 1:
        return left[0]
    if not left:
        raise m.end(
            Status.NO_MATCH,
            "every building that matched lies off the target's outline from closer",
        )
    first, rival = sorted(left, key=lambda f: -f.score)[:2]
    why = (
        "their outlines lie on the target's as closely as these photos tell"
        if first.outline_compared and rival.outline_compared
        else "they show parts at several heights, so their outlines cannot be compared"
    )
    raise m.end(
        Status.NO_MATCH,
        f"points of interest {first.poi.index} and {rival.poi.index} both match the "
        f"target (scores {first.score:.3f} and {rival.score:.3f}) and {why}: which is "
        "the target is not known",
    )


def _by_tiers(m: SearchMission, left: list[Found]) -> Wait[list[Found]]:
    """The buildings among ``left`` (all matched a target picture that shows a higher
    part's walls inside its roof, their outlines not compared) that may still be the target.
    One whose roof shows no higher part in a photo taken as the picture was (`_tier_look`)
    is not: seen from over the same point of it, drawn at least as large, a higher part's
    walls would show at least as long as the picture shows them. A building almost the
    target but flat (its outline's near shape at one height) shows none; the mission ends
    NO_MATCH when every one is such (world 50350: the best match, a near shape with an arm
    shorter, was flat). When one alone shows a higher part and every other was seen
    without, it is the target; else ``left`` is left as it is (a photo could not be taken,
    or several show one): one never seen to show a higher part is not called the target for
    the others having shown none."""
    seen: list[bool | None] = []
    for f in left:  # a comprehension may not yield
        seen.append((yield from _higher_part(m, f, left)))  # noqa: PERF401
    if all(s is False for s in seen):
        where = "where the picture shows one"
        if len(left) == 1:
            raise m.end(
                Status.NO_MATCH,
                f"point of interest {left[0].poi.index} matches the target (score "
                f"{left[0].score:.3f}), but its roof, photographed as the target picture was, "
                f"shows no higher part {where}: it is not the target",
            )
        raise m.end(
            Status.NO_MATCH,
            f"points of interest {', '.join(str(f.poi.index) for f in left)} match the "
            "target, but none of their roofs, photographed as the target picture was, shows a "
            f"higher part {where}: none is the target",
        )
    shown = [f for f, s in zip(left, seen, strict=True) if s]
    if len(left) > 1 and len(shown) == 1 and seen.count(False) == len(left) - 1:
        m.event(
            Level.INFO,
            f"point of interest {shown[0].poi.index}: the only one whose roof shows a higher "
            "part, as the target picture does",
        )
        return shown
    # one left but never seen to show a higher part: the photo that ruled the others out
    # may have hidden the target's walls (the light, the way it was reached); no conclusion
    return left


def doubts_by_tiers(
    m: SearchMission,
    best: Found,
    doubts: list[tuple[int, Look]],
    pois: tuple[PointOfInterest, ...],
) -> Wait[list[tuple[int, Look]]]:
    """The buildings of the target's hue left in doubt (``doubts``: scored under the
    threshold from too far to tell, their outlines not compared) that may still be the
    target, when the target picture shows a higher part's walls and ``best``'s roof shows
    one: not those whose roof, photographed as the picture was, shows none (`_by_tiers`)."""
    if not (yield from _higher_part(m, best, [best])):
        return doubts
    left = []
    for k, look in doubts:
        f = found(pois[k], look, None)
        if (yield from _higher_part(m, f, [best, f])) is not False:
            left.append((k, look))
    return left


def _higher_part(m: SearchMission, f: Found, among: list[Found]) -> Wait[bool | None]:
    """Whether ``f``'s roof shows a higher part's walls: in the look that matched it, else
    in a photo taken as the target picture was (`_tier_look`; None when that tells
    nothing). Each building is photographed so once (``SearchMission.higher_parts``);
    ``among``: the buildings it is to be told from."""
    k = f.poi.index
    if k in m.higher_parts:
        return m.higher_parts[k]
    nadir = nadir_px(f.photo.pose, f.photo.intrinsics)
    seen: bool | None = True
    if not shows_higher_part(m.params, f.photo.image_rgb, f.shape, nadir):
        seen = yield from _tier_look(m, f, among)
    if seen is False:
        m.event(
            Level.INFO,
            f"point of interest {k}: photographed as the target picture was, its roof shows "
            "no higher part where the picture shows one: not the target",
        )
    m.higher_parts[k] = seen
    return seen


def _tier_look(m: SearchMission, f: Found, left: list[Found]) -> Wait[bool | None]:
    """Whether ``f``'s roof shows a higher part's walls (`shows_higher_part`) in a photo
    straight down from over the point of it the target picture was taken from over (the
    picture's centre, carried onto ``f``'s outline by the match), drawn at least as large
    as the picture draws the target. Lower than the look that matched only as far as that
    size needs (`resolving_altitude_m`): were ``f`` the target, the camera would stand as
    far above each of its parts as the picture's did. None when no such photo can be taken
    (the floor over roofs of unknown height, the ceiling), it does not show the roof whole,
    or it shows no higher part but draws the roof smaller than the picture draws the target
    (the way there may have held it higher): then it says nothing."""
    p = m.params
    photo, k = f.photo, f.photo.intrinsics
    _, matches = best_match(m.target, (f.shape,), p.recognize)
    at = carried_point(m.target, f.shape, matches[0], m.target_nadir_px)
    if at is None:
        return None
    alt_was = photo.pose.pos_enu_m[2]
    plane = min(f.roof_m, alt_was - 1.0)
    try:
        x, y = ground_point(*at, photo.pose, k, plane_z_m=plane)
        ring = ground_polygon(f.shape.polygon_px, photo.pose, k, plane_z_m=plane)
    except NavError:
        return None
    as_large = resolving_altitude_m(m, f.shape, alt_was, plane, ring, (x, y), k)
    whole = whole_altitude_m(m, plane, ring, (x, y), k)
    alt = max(min(alt_was, as_large), whole, plane + p.mission.min_above_roof_m, m.floor_at(x, y))
    if m.ceiling_m is not None and alt > m.ceiling_m:
        return None
    others = ", ".join(str(o.poi.index) for o in left if o is not f)
    what = (
        f"point of interest {f.poi.index}: over where the target picture was taken from, "
        f"to tell it from {others} by a higher part"
    )
    yield from shift(m, (x, y, alt), what)
    # the way may have crossed roofs of unknown height higher than the floor here: down
    # again, straight, to the altitude that draws it as large as the picture
    here = m.last.pos_enu_m if m.last is not None else (x, y, alt)
    if here[2] > alt + p.mission.arrive_radius_m:
        yield from m.move((x, y, alt), None, f"{what}: down to {alt:.1f} m")
    there = yield from m.photo(f"poi-{f.poi.index}-tiers", -90.0)
    shapes = photo_shapes(m, there)
    roof = [
        s
        for s in shapes
        if of_target_hue(m, s.colour_rgb) and not s.cut_by_border and _inside_roof(f, there, s)
    ]
    if not roof:
        return None
    shape = max(roof, key=lambda s: s.area_px)
    if shows_higher_part(p, there.image_rgb, shape, nadir_px(there.pose, there.intrinsics)):
        return True  # seen, at whatever size
    # none seen: that says it has none only if drawn as large as the picture, each drawing
    # known to its outline's accuracy all round
    off = outline_accuracy_px(p.vectorize)
    drawn = math.sqrt(max(shape.area_px, 1.0))
    if 2.0 * drawn - less_accuracy(shape, off) < less_accuracy(m.target, off):
        return None
    return False


def _inside_roof(f: Found, photo: Photo, shape: Shape) -> bool:
    """Whether a point inside ``shape`` (in ``photo``), on ``f``'s roof's plane, lies on
    that roof: `on_roof` with a point the outline holds, where an L's centroid may fall
    in its notch."""
    u, v = shapely.Polygon(shape.polygon_px).representative_point().coords[0]
    return point_on_roof(f, photo, (float(u), float(v)))


def _rivals_of(m: SearchMission, best: Found, matches: list[Found]) -> list[Found]:
    """The other buildings that matched and nothing yet tells from ``best``: not ``best``'s
    own roof seen again, and showing as many courtyards as the target picture if ``best``
    does — and, unless the target picture shows parts at several heights (whose walls each
    photo's perspective shows or hides), as many openings inside the roof (a courtyard whose
    floor does not show: `enclosed_openings`)."""
    holes = len(m.target.holes_px)
    rivals = []
    for f in matches:
        if f.poi.index == best.poi.index or on_roof(best, f.photo, f.shape):
            continue
        # a courtyard more or less than the target picture shows tells it apart
        if len(f.shape.holes_px) != holes and len(best.shape.holes_px) == holes:
            continue
        want = m.target_openings
        if not m.target_stepped and _openings(m, f) != want and _openings(m, best) == want:
            m.event(
                Level.INFO,
                f"point of interest {f.poi.index}: its roof shows {_openings(m, f)} opening(s) "
                f"inside its outline, the target picture's and {best.poi.index}'s "
                f"{want}: not the target",
            )
            continue
        rivals.append(f)
    return rivals


def _openings(m: SearchMission, f: Found) -> int:
    """How many openings ``f``'s roof shows inside its outline (`enclosed_openings`)."""
    least = m.params.vectorize.min_hole_area_px
    return enclosed_openings(f.photo.image_rgb, f.shape, least_px=least)


def _look_closer(m: SearchMission, f: Found, left: list[Found]) -> Wait[Judgement | None]:
    """A look at ``f``'s building from where it fills ``mission.top_fill`` of the photo, and
    its judgement; None when its roof is not measured (no descent toward a roof of unknown
    height) or that is not clearly closer than the look that matched."""
    p = m.params.mission
    poi, photo = f.poi, f.photo
    if not f.roof_measured:
        return None
    k = photo.intrinsics
    alt_was = photo.pose.pos_enu_m[2]
    plane = min(f.roof_m, alt_was - 1.0)
    try:
        ring = ground_polygon(f.shape.polygon_px, photo.pose, k, plane_z_m=plane)
        x, y = ground_point(*f.shape.centroid_px, photo.pose, k, plane_z_m=plane)
    except NavError:
        return None
    extent = math.dist(*farthest_pair(ring))
    fit = fit_altitude_m(roof_m=f.roof_m, extent_m=extent, intrinsics=k, fill=p.top_fill)
    lower = max(fit, f.roof_m + p.min_above_roof_m)
    clear = alt_was - p.recheck_climb_m / 2.0
    if lower <= clear < m.floor_at(x, y):  # held up by roofs of unknown height: the look
        m.measure_near(x, y, photo, photo_shapes(m, photo))  # that matched may measure them
    alt = max(lower, m.floor_at(x, y))
    if alt > clear:
        return None
    others = ", ".join(str(o.poi.index) for o in left if o is not f)
    yield from shift(
        m, (x, y, alt), f"point of interest {poi.index}: closer, to tell it from {others}"
    )
    look = yield from take_look(m, poi.index, p.max_looks + 1, alt, poi.colour_rgb)
    return look.judgement
