"""The search: visit the points of interest, photograph each from above and compare it with
the target. A doubtful photo (the candidate has the target's hue but is cut by the image
border, scores just below the threshold, or lies off-centre) is not the last word: like a
pilot, the mission climbs over the candidate's roof and looks again. From higher up the
whole roof fits the photo and the perspective steps between roofs of different heights
shrink (on ``paper``, over headings and ±0.5 m: 65 % of photos from 20 m match, all from
30 m)."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import cv2
import numpy as np

from uavtool.camera import Intrinsics
from uavtool.mission.analysis import (
    ONE_ROOF_PX,
    Judgement,
    aimed_shape,
    not_flat,
    roof_between,
    same_roof_aside,
)
from uavtool.mission.looks import (
    Found,
    Look,
    farthest_pair,
    found,
    of_target_hue,
    on_roof,
    other_outline,
    photo_shapes,
    resolving_altitude_m,
    shift,
    take_look,
)
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest, Status, Vec3
from uavtool.mission.settle import doubts_by_tiers, settle
from uavtool.mission.unknown import shows_as
from uavtool.nav import NavError, ground_point, ground_polygon, visit_order
from uavtool.nav.heights import fit_altitude_m
from uavtool.nav.parallax import roof_by_alignment
from uavtool.vision import Shape
from uavtool.vision.vectorize import enclosed_openings, outline_mask, same_paint

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


def look_altitude_m(
    m: SearchMission, poi: PointOfInterest, intrinsics: Intrinsics, roof_m: float | None = None
) -> float:
    """Where to look at ``poi`` from: its footprint spans ``look_fill`` of the photo, and the
    camera is at least ``min_above_roof_m`` over its roof (``roof_m``, if given, else the
    point of interest's)."""
    p = m.params.mission
    roof = poi.roof_m if roof_m is None else roof_m
    fit = fit_altitude_m(
        roof_m=roof, extent_m=poi.extent_m, intrinsics=intrinsics, fill=p.look_fill
    )
    return max(fit, roof + p.min_above_roof_m)


def search(
    m: SearchMission,
    pois: tuple[PointOfInterest, ...],
    order: tuple[int, ...],
    *,
    overview: Photo,
    overview_shapes: tuple[Shape, ...],
    transit_m: float,
    roofless: frozenset[int] = frozenset(),
    inspector: Inspector | None = None,
) -> Wait[Found | None]:
    """Visit the points of interest in order (across at ``transit_m``, over every known
    roof); the best match (the first one unless ``visit_all``); ends the mission with
    NO_MATCH when nothing matched. A look at a point of interest whose overview shape shows
    no roof (``roofless``: walls, a darker shade) matches only a building that explains
    that shape."""
    p = m.params.mission
    best: Found | None = None
    best_score, best_poi = 0.0, -1
    matches: list[Found] = []  # every building that matched, in turn
    unjudged: list[tuple[int, Look]] = []  # of the target's hue, never judged
    doubtful: list[tuple[int, Look, bool]] = []  # of the target's hue, judged in doubt
    todo = list(order)
    look_at: Inspector = inspector or (
        lambda k, _todo: inspect(m, k, pois, overview, overview_shapes, transit_m)
    )
    while todo:
        k = todo.pop(0)
        poi = pois[k]
        looks, upper = yield from look_at(k, todo)
        # a building of another colour is no near miss, however alike its outline
        top = max((look.judgement.score for look in looks if look.judgement.same_hue), default=0.0)
        if top > best_score:
            best_score, best_poi = top, k
        look = looks[-1]  # a match ends the looking: the last look is the match if any
        j = look.judgement
        if (left := _left_unjudged(looks)) is not None:
            unjudged.append((k, left))
        elif (doubt := _doubtful(m, looks)) is not None:
            doubtful.append((k, *doubt))
        if (
            j.matched
            and poi.shape_index in roofless
            and not shows_as(
                look.shapes[j.candidate],
                look.photo,
                overview_shapes[poi.shape_index],
                overview,
                poi.roof_m if upper is None else upper,
            )
        ):
            m.event(
                Level.INFO,
                f"point of interest {k}: the match is another building than the one seen there "
                "(walls or a darker shade of the target's hue): not its match",
            )
            continue
        if j.matched and best is not None and _shows_again(best, look):
            m.event(
                Level.INFO,
                f"point of interest {k}: the look shows point of interest {best.poi.index}'s "
                "building again, no rival",
            )
        elif j.matched and (best is None or _beats(m, k, look, best)):
            shape = look.shapes[j.candidate]
            seen = overview_shapes[poi.shape_index]
            roof = roof_between(seen, overview, shape, look.photo)
            if roof is None or roof > p.assumed_roof_m:  # beyond the tallest expected: a
                roof = yield from m.measure_roof(k, poi, look, shape)  # mismatch
            best = found(poi, look, roof)
            matches.append(best)
            if not p.visit_all:
                todo = _rivals(m, pois, todo, k)
        elif j.matched:  # a match that does not beat the best: still a rival's evidence
            shape = look.shapes[j.candidate]
            # its roof as the overview and the look tell it, else measured from another
            # altitude as the best's is: a closer look may then descend toward it and tell
            # it from the best (world 50001: an arm shorter, 3.5 % off the target's outline
            # within the 3.7 % its look from over the highest it might be allowed)
            roof = roof_between(overview_shapes[poi.shape_index], overview, shape, look.photo)
            if roof is None or roof > p.assumed_roof_m:
                roof = yield from m.measure_roof(k, poi, look, shape)
            matches.append(found(poi, look, roof))
    if best is None:
        where = f"best score {best_score:.3f} at point of interest {best_poi}"
        if best_poi < 0:
            where = "none of the target's colour"
        unseen = "".join(
            f"; {k}, of the target's colour, could not be judged ({_why_unjudged(look.judgement)})"
            for k, look in unjudged
        )
        raise m.end(Status.NO_MATCH, f"no building matched the target ({where}){unseen}")
    _judged_all(m, best, unjudged)
    # a match by score alone (its outline not compared) leaves any doubt standing; one
    # whose outline lies on the target's, only a doubt of walls (its rival's outline was
    # told apart from the target's, but may hold walls)
    doubts = [(k, look) for k, look, walls in doubtful if walls or not best.outline_compared]
    if doubts and m.target_tiers and not best.outline_compared:
        doubts = yield from doubts_by_tiers(m, best, doubts, pois)
    _judged_all(m, best, doubts)
    best = yield from settle(m, best, matches)
    m.event(
        Level.INFO,
        f"target is point of interest {best.poi.index} (score {best.score:.3f}), "
        + (
            f"roof {best.roof_m:.1f} m above home"
            if best.roof_measured
            else f"roof not measured (assumed {best.roof_m:.1f} m above home)"
        ),
    )
    return best


Inspection = tuple[list["Look"], float | None]
"""What the looks at one point of interest found: the looks in order, and the highest its
roof may be when its height is unknown (else None)."""


Inspector = Callable[[int, list[int]], "Wait[Inspection]"]
"""How the search has point of interest ``k`` looked at, told which are still to come (a
fleet's leader hands them to the others ahead of time)."""


def inspect(
    m: SearchMission,
    k: int,
    pois: tuple[PointOfInterest, ...],
    overview: Photo,
    overview_shapes: tuple[Shape, ...],
    transit_m: float,
) -> Wait[Inspection]:
    """Fly to point of interest ``k`` (across at ``transit_m``) and look at it, from closer
    or again as the looks ask, up to ``mission.max_looks``."""
    p = m.params.mission
    ceiling_m = overview.pose.pos_enu_m[2]
    poi = pois[k]
    x, y = poi.pos_en_m
    # a roof of unknown height is looked at from over the highest it may be: a closer
    # look follows only once a look has measured it
    upper = None if poi.roof_measured else m.unknown.get(poi.shape_index, (None, ceiling_m))[1]
    alt = min(look_altitude_m(m, poi, overview.intrinsics, upper), ceiling_m)
    alt = max(alt, m.floor_at(x, y))
    yield from m.travel((x, y, alt), None, transit_m, f"point of interest {k}")
    m.visited.append(k)
    looks = [(yield from take_look(m, k, 1, alt, poi.colour_rgb))]
    roof_m = poi.roof_m
    sided = False  # a look from beside the first, to measure a roof by parallax, taken
    for n in range(2, p.max_looks + 1):
        closer = None
        # a roof the overview's border cut was measured by the edges it shows: for plans,
        # not to descend by (it counts as high as its region allows); whole in the looks,
        # they measure it
        known = poi.roof_measured and poi.shape_index not in m.unknown
        if not known:
            before = [(overview_shapes[poi.shape_index], overview)] + [
                (look.shapes[look.judgement.candidate], look.photo)
                for look in looks[:-1]
                if look.judgement.candidate >= 0
            ]
            closer = _closer_look(m, looks[-1], before, poi.shape_index)
        elif looks[-1].judgement.too_small:
            closer = _closer_look(m, looks[-1], [], poi.shape_index, roof_m)
        still = None if known else m.unknown.get(poi.shape_index)
        step = None
        if closer is None and still is not None:
            step = _step_down(m, looks[-1], still.upper_m)
        if closer is None and step is None and still is not None and not sided:
            aside = _side_step(m, looks[-1])
            if aside is not None:
                sided = True
                off = math.dist(aside[:2], looks[-1].photo.pose.pos_enu_m[:2])
                m.event(
                    Level.INFO,
                    f"point of interest {k}: drawn too small to judge; its roof not measured "
                    f"(at most {still.upper_m:.1f} m above home) and no lower look is clear: "
                    f"looking again from {off:.1f} m aside, at {aside[2]:.1f} m, to measure it",
                )
                yield from shift(m, aside, f"point of interest {k}, look {n}")
                same = functools.partial(
                    _same_aside, looks[-1], still.upper_m, m.params.vectorize.rdp_epsilon_px
                )
                looks.append((yield from take_look(m, k, n, aside[2], poi.colour_rgb, same)))
                continue
        if step is not None and still is not None:
            m.event(
                Level.INFO,
                f"point of interest {k}: drawn too small to judge; its roof not measured (at "
                f"most {still.upper_m:.1f} m above home): looking again from straight above "
                f"it, at {step[2]:.1f} m",
            )
            yield from m.travel(step, None, transit_m, f"point of interest {k}, look {n}")
            looks.append((yield from take_look(m, k, n, step[2], poi.colour_rgb)))
            continue
        if closer is not None:
            pos, roof_m = closer
            j = looks[-1].judgement
            why = (
                "drawn too small to judge"
                if j.too_small
                else f"score {j.score:.3f} just below the threshold"
            )
            m.event(
                Level.INFO,
                f"point of interest {k}: {why}; its roof measured {roof_m:.1f} m above home: "
                f"looking again from closer, at {pos[2]:.1f} m",
            )
            yield from m.travel(pos, None, transit_m, f"point of interest {k}, look {n}")
            looks.append((yield from take_look(m, k, n, pos[2], poi.colour_rgb)))
            continue
        again = _look_again(m, looks[-1], roof_m, ceiling_m)
        if again is None:
            break
        pos, why = again
        m.event(
            Level.INFO,
            f"point of interest {k}: {why}; looking again from above its roof at {pos[2]:.1f} m",
        )
        yield from shift(m, pos, f"point of interest {k}, look {n}")
        looks.append((yield from take_look(m, k, n, pos[2], poi.colour_rgb)))
    return looks, upper


def _left_unjudged(looks: list[Look]) -> Look | None:
    """The look that left a building of the target's hue unjudged (drawn too small, cut by
    the border), unless a later look judged one: a later look that shows none (a look
    from aside that could not tell the building apart from others, world 50023) leaves it
    unjudged all the same, and the search may not call another building the target."""
    left = None
    for look in looks:
        j = look.judgement
        if j.candidate >= 0 and j.same_hue:
            left = None if j.judgeable else look
    return left


def _doubtful(m: SearchMission, looks: list[Look]) -> tuple[Look, bool] | None:
    """The look that left a point of interest in doubt, if the looks did, and whether the
    doubt is its walls: a candidate of the target's hue that no look matched, and either

    - scored between ``mission.recheck_min_score`` and the threshold, none of its outlines
      told apart from the target's (`other_outline`): the looks asked to see it again,
      closer or higher, and ran out; a score from afar says little of a building whose
      parts stand at several heights (False);
    - or its outline was told apart from the target's only by a look whose outline may
      hold the building's own walls (`_walls_inside`): a wall lit within the vectorizer's
      shade tolerance of the roof joins the roof's outline (True).

    A look that drew it as the target's mirror image (`Judgement.mirror_image`) tells it
    apart: no doubt."""
    threshold = m.params.recognize.threshold
    least = m.params.mission.recheck_min_score
    judged = [
        look
        for look in looks
        if look.judgement.candidate >= 0 and look.judgement.same_hue and look.judgement.judgeable
    ]
    if any(look.judgement.matched for look in judged):
        return None
    if any(look.judgement.mirror_image for look in judged):
        return None  # the target's mirror image: another building, whatever it scored
    apart = [look for look in judged if other_outline(look.judgement)]
    if apart:
        if all(_walls_inside(m, look) for look in apart):
            return max(apart, key=lambda look: look.judgement.score), True
        return None  # a near shape, told apart clearly
    doubts = [look for look in judged if least <= look.judgement.score < threshold]
    if not doubts:
        return None
    return max(doubts, key=lambda look: look.judgement.score), False


def _walls_inside(m: SearchMission, look: Look) -> bool:
    """Whether the look's candidate outline holds what may be the building's own walls:
    at least ``vectorize.min_area_px`` pixels inside it (a pixel in from its edge) of its
    paint (`same_paint`) whose brightness differs from the roof's by more than the roof's
    own spread (three median deviations, at least 2 DN) but no more than
    ``vectorize.roof_value_tolerance``, the most the vectorizer ever takes a shade for roof
    within (in a noisy photo; `uavtool.vision.roof.roof_tolerance`). A lit wall, seen from
    close, then moves the outline by its width (world scene 50334: the target's inner
    corner, 15 DN brighter than its roof, put its outline 12.9 % off)."""
    shape = look.shapes[look.judgement.candidate]
    image = look.photo.image_rgb
    inside = cv2.erode(outline_mask(image, shape), np.ones((3, 3), np.uint8)) > 0
    value = image.max(axis=2)[inside].astype(np.int16)
    if value.size == 0:
        return False
    differ = np.abs(value - max(shape.colour_rgb))
    half = differ.size // 2
    spread = int(np.partition(differ, half)[half])  # the median (np.median imports numpy.ma)
    shaded = (
        same_paint(image, shape.colour_rgb)[inside]
        & (differ > max(3 * spread, 2))
        & (differ <= m.params.vectorize.roof_value_tolerance)
    )
    return int(np.count_nonzero(shaded)) >= m.params.vectorize.min_area_px


def _judged_all(m: SearchMission, best: Found, unjudged: list[tuple[int, Look]]) -> None:
    """End the mission NO_MATCH when a building of the target's hue other than ``best``'s
    was never judged (drawn too small to tell its outline, or cut by the border, however
    it was looked at): it may be the target, and ``best`` a building almost like it."""
    for k, look in unjudged:
        shape = look.shapes[look.judgement.candidate]
        if k == best.poi.index or on_roof(best, look.photo, shape):
            continue
        why = _why_unjudged(look.judgement)
        raise m.end(
            Status.NO_MATCH,
            f"point of interest {best.poi.index} matches the target (score {best.score:.3f}), "
            f"but {k}, of the target's colour, could not be judged ({why}): which is the "
            "target is not known",
        )


def _why_unjudged(j: Judgement) -> str:
    """Why a look left its candidate unjudged (`_judged_all`)."""
    if j.too_small:
        return "drawn too small to tell its outline"
    if not j.judgeable:
        return "cut by the image border"
    if other_outline(j):
        return f"its outline, {j.outline_gap * 100:.1f} % off, may hold its own walls"
    return f"scored {j.score:.3f} from too far to tell, and could not be looked at closer"


def _shows_again(best: Found, look: Look) -> bool:
    """Whether a look's matched candidate is the building already matched (``best``): its
    centre, on the matched roof's plane, lies on that roof. A look aimed at a rival of the
    target's hue (walls whose roof the overview did not show) may find the matched
    building nearer its centre; that is no new evidence."""
    return on_roof(best, look.photo, look.shapes[look.judgement.candidate])


def _beats(m: SearchMission, k: int, look: Look, best: Found) -> bool:
    """Whether point of interest ``k``'s match (``look``) is the target rather than ``best``:
    the higher score, unless the two differ by no more than pixel noise
    (``recognize.mirror_tolerance``, as the mirror rule takes it). Then the outline cannot
    tell them apart, and what lies inside it may: openings in the roof (a courtyard whose
    floor does not show, a higher part's walls; `enclosed_openings`). The one with as many
    as the target picture wins, if only one has."""
    j = look.judgement
    if abs(j.score - best.score) > m.params.recognize.mirror_tolerance:
        return j.score > best.score
    least = m.params.vectorize.min_hole_area_px
    want = m.target_openings
    here = enclosed_openings(look.photo.image_rgb, look.shapes[j.candidate], least_px=least)
    there = enclosed_openings(best.photo.image_rgb, best.shape, least_px=least)
    if (here == want) == (there == want):
        return j.score > best.score
    winner, loser, shown = (k, best.poi.index, there) if here == want else (best.poi.index, k, here)
    m.event(
        Level.INFO,
        f"points of interest {k} and {best.poi.index} match as well (scores {j.score:.3f} and "
        f"{best.score:.3f}); {loser}'s roof shows {shown} opening(s) inside its outline, the "
        f"target picture's {want}: {winner} is the better match",
    )
    return here == want


def target_hue_first(
    m: SearchMission, start: tuple[float, float], pois: tuple[PointOfInterest, ...]
) -> tuple[int, ...]:
    """The order to visit ``pois`` in from ``start``: the shortest way over those of the
    target's hue (:func:`of_target_hue`), then on from the last of them over the others; the
    shortest way over all when every one is visited anyway (``mission.visit_all``). Only a
    building of the target's hue can match, and once one has, the search looks only at the
    others of its hue (:func:`_rivals`): a building of another colour visited first is time
    spent before the match, never a match."""
    every = list(range(len(pois)))
    like = [k for k in every if of_target_hue(m, pois[k].colour_rgb)]
    if m.params.mission.visit_all or not like or len(like) == len(pois):
        return visit_order(start, [poi.pos_en_m for poi in pois])
    rest = [k for k in every if k not in like]
    first = [like[i] for i in visit_order(start, [pois[k].pos_en_m for k in like])]
    last = pois[first[-1]].pos_en_m
    return (*first, *(rest[i] for i in visit_order(last, [pois[k].pos_en_m for k in rest])))


def _rivals(
    m: SearchMission, pois: tuple[PointOfInterest, ...], todo: list[int], matched: int
) -> list[int]:
    """The points of interest still to visit that could be the target as well (its colour,
    within the match's hue gate): a match is final only once none is left unseen, so a slab
    in the target's colour never wins over the courtyard building further on."""
    rivals = [k for k in todo if of_target_hue(m, pois[k].colour_rgb)]
    if rivals:
        m.event(
            Level.INFO,
            f"point of interest {matched} matches; before deciding, looking at the others of the "
            f"target's colour: {', '.join(map(str, rivals))}",
        )
    return rivals


def measure_from_another_altitude(
    m: SearchMission, k: int, poi: PointOfInterest, look: Look, shape: Shape
) -> Wait[float | None]:
    """The matched roof's height when the overview could not tell it (cut by its border):
    one more photo straight below the look, ``overview_climb_m`` lower (never closer than
    ``min_above_roof_m`` over the roof as assumed, nor below the floor there), compared with
    the look by size; straight above it instead (never above the ceiling) when the floor
    there — the highest a roof of unknown height, this one too, may be — allows no lower
    photo."""
    p = m.params.mission
    x, y, alt = look.photo.pose.pos_enu_m
    lower = max(alt - p.overview_climb_m, poi.roof_m + p.min_above_roof_m, m.floor_at(x, y))
    higher = min(alt + p.overview_climb_m, m.ceiling_m if m.ceiling_m is not None else alt)
    if shape.cut_by_border:
        return None
    if lower <= alt - p.overview_climb_m / 2.0:
        there = lower
    elif higher >= alt + p.overview_climb_m / 2.0:
        there = higher
    else:
        return None
    yield from m.move((x, y, there), None, f"point of interest {k}, measuring its roof")
    photo = yield from m.photo(f"poi-{k}-roof", -90.0)
    candidate = aimed_shape(m.params, photo_shapes(m, photo), photo.intrinsics, shape.colour_rgb)
    if candidate is None:
        return None
    roof = roof_between(shape, look.photo, candidate, photo)
    m.event(
        Level.INFO,
        f"point of interest {k}: roof "
        + (f"{roof:.1f} m above home" if roof is not None else "height not measurable"),
    )
    # Taller than expected is believed (a tower): the side photos then stand further off.
    return roof if roof is not None and roof < min(alt, there) - 1.0 else None


def _closer_look(
    m: SearchMission,
    look: Look,
    before: list[tuple[Shape, Photo]],
    index: int,
    roof_m: float | None = None,
) -> tuple[Vec3, float] | None:
    """Where to look again from, lower, and the roof height, when the look's candidate has
    the target's hue and is drawn too small to judge, or (a roof of unknown height, looked
    at from over the tallest it may be) scores just below the threshold. The roof is
    ``roof_m`` when measured; else the candidate, whole in the look and in an earlier photo
    of it (``before``: the overview's shape, the earlier looks' candidates; the one
    furthest in altitude that tells), gives its height. The altitude is where the candidate
    fills the photo as a look should or, drawn too small, where it is drawn as large as
    judging it needs (`resolving_altitude_m`). None when that is not clearly lower (by
    half ``recheck_climb_m``) or the height cannot be told."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or other_outline(j):
        return None
    if not j.too_small and (not j.judgeable or j.score < p.recheck_min_score):
        return None  # a score from too far says nothing: only from closer
    shape = look.shapes[j.candidate]
    alt = photo.pose.pos_enu_m[2]
    roof = roof_m
    if roof is None:
        heights = (
            roof_between(seen, earlier, shape, photo)
            for seen, earlier in sorted(before, key=lambda b: -abs(b[1].pose.pos_enu_m[2] - alt))
        )
        roof = next((h for h in heights if h is not None), None)
        if roof is None and j.too_small:
            roof = _aligned_roof(m, shape, photo, before, index)
        # a roof no closer look could clear is no height to learn (a mismatched pair); one
        # taller than the tallest expected is believed (a tower: 25.4 m for a 25 m roof
        # was once refused, and the target never looked at from closer)
        if roof is None or roof + p.min_above_roof_m > look.alt_m - p.recheck_climb_m / 2.0:
            return None
    k = photo.intrinsics
    plane = min(roof, look.alt_m - 1)
    ring = ground_polygon(shape.polygon_px, photo.pose, k, plane_z_m=plane)
    if roof_m is None:
        m.learn_roof(index, ring, roof)  # measured: a look may now descend near it
    extent = math.dist(*farthest_pair(ring))
    u, v = shape.centroid_px
    x, y = ground_point(u, v, photo.pose, k, plane_z_m=plane)
    fit = fit_altitude_m(roof_m=roof, extent_m=extent, intrinsics=k, fill=p.look_fill)
    if j.too_small:
        fit = min(fit, resolving_altitude_m(m, shape, alt, roof, ring, (x, y), k))
    lower = max(fit, roof + p.min_above_roof_m)
    clear = look.alt_m - p.recheck_climb_m / 2.0
    if lower <= clear < m.floor_at(x, y):  # held up by roofs of unknown height: the look
        m.measure_near(x, y, photo, look.shapes)  # may measure them
    lower = max(lower, m.floor_at(x, y))
    if lower > clear:
        return None
    return (x, y, lower), roof


def _aligned_roof(
    m: SearchMission, shape: Shape, photo: Photo, before: list[tuple[Shape, Photo]], index: int
) -> float | None:
    """The highest the roof of ``shape`` (a look's candidate in ``photo``, drawn too small
    for two outlines to place it: `roof_between`) may stand, by lining ``photo`` up with
    an earlier photo of it (``before``: its shape there and the photo, the one from
    furthest first) plane by plane (`roof_by_alignment`), up to the highest it may be. The
    sweep is made both ways, each photo's drawing of it carried onto the other's: a larger
    roof of its colour in one photo lines it up at that roof's height one way only. The
    higher answer of the two, when both tell and neither photo shows walls inside the
    outline standing above it (`not_flat`)."""
    if shape.cut_by_border:
        return None
    still = m.unknown.get(index)
    alt = photo.pose.pos_enu_m[2]
    top = min(still.upper_m if still is not None else alt, alt) - 1.0
    least = m.params.vectorize.min_area_px
    away = sorted(before, key=lambda b: -math.dist(b[1].pose.pos_enu_m, photo.pose.pos_enu_m))
    for seen, earlier in away:
        if seen.cut_by_border:
            continue
        top_here = min(top, earlier.pose.pos_enu_m[2] - 1.0)
        ways = ((shape, photo, earlier), (seen, earlier, photo))
        told = [
            roof_by_alignment(
                outline_mask(a.image_rgb, s),
                s.colour_rgb,
                a.image_rgb,
                a.pose,
                b.image_rgb,
                b.pose,
                a.intrinsics,
                top_m=top_here,
                least_px=least,
            )
            for s, a, b in ways
        ]
        if any(h is None for h in told):
            continue
        roof = max(h for h in told if h is not None)
        # one plane may line up a building of tiers too, between them: as `roof_between`,
        # nothing inside either outline may stand higher
        if not (
            not_flat(shape, photo, roof, earlier, seen)
            or not_flat(seen, earlier, roof, photo, shape)
        ):
            return roof
    return None


def _step_down(m: SearchMission, look: Look, upper_m: float) -> Vec3 | None:
    """Where to look again from when the look's candidate, of the target's hue, is drawn
    too small to judge and its roof's height is not known, only the highest it may be
    (``upper_m``): over where it stands were it that high, as low as keeps it whole in the
    photo (filling at most ``mission.top_fill`` of it) whatever its height, and no lower
    than the floor there. Its size in the two photos then tells its height, and the new
    photo draws it larger. None when that is not clearly lower (by half
    ``recheck_climb_m``)."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or not j.too_small:
        return None
    shape = look.shapes[j.candidate]
    if shape.cut_by_border:
        return None
    k = photo.intrinsics
    alt = photo.pose.pos_enu_m[2]
    top = min(upper_m, alt - 1.0)
    span_px = math.dist(*farthest_pair(tuple(map(tuple, shape.polygon_px))))
    # drawn largest, were its roof as high as it may be: span_px (alt - top) / (z - top)
    z = top + (alt - top) * span_px / (p.top_fill * min(k.width_px, k.height_px))
    try:
        x, y = ground_point(*shape.centroid_px, photo.pose, k, plane_z_m=top)
        low = ground_point(*shape.centroid_px, photo.pose, k, plane_z_m=0.0)
    except NavError:
        return None
    z = max(z, top + p.min_above_roof_m, m.floor_at(x, y), m.floor_at(*low))
    if z > alt - p.recheck_climb_m / 2.0:
        return None
    return (x, y, z)


def _side_step(m: SearchMission, look: Look) -> Vec3 | None:
    """Where to look again from when the look's candidate, of the target's hue, is drawn
    too small to judge, its roof's height is unknown and no lower look is clear of what may
    stand there (`_step_down`): at the look's altitude, a baseline aside along the photo's
    long side, toward the candidate, so that the two photos measure its roof by parallax
    (`roof_between`, then `_closer_look`). A roof ``D`` below the camera shifts by
    ``f b / D`` pixels between them and outlines are placed within ``ONE_ROOF_PX``: the
    baseline ``b`` keeps the height's error within half ``mission.min_above_roof_m`` even
    for a roof on the ground, the farthest it may be. A roof so high that it slides out of
    the second photo is not measured (another shape there does not explain both outlines
    at one height). None when the look's candidate does not ask for it."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or not j.too_small:
        return None
    k = photo.intrinsics
    x0, y0, alt = photo.pose.pos_enu_m
    baseline = alt * alt * ONE_ROOF_PX / (k.fx_px * p.min_above_roof_m / 2.0)
    toward = 1.0 if look.shapes[j.candidate].centroid_px[0] >= k.cx_px else -1.0
    try:
        a = ground_point(k.cx_px, k.cy_px, photo.pose, k, plane_z_m=0.0)
        b = ground_point(k.cx_px + toward * k.width_px / 4.0, k.cy_px, photo.pose, k, plane_z_m=0.0)
    except NavError:
        return None
    run = math.dist(a, b)
    if run <= 0.0:
        return None
    return (x0 + (b[0] - a[0]) / run * baseline, y0 + (b[1] - a[1]) / run * baseline, look.alt_m)


def _same_aside(
    first: Look, upper_m: float, outline_px: float, shapes: tuple[Shape, ...], photo: Photo
) -> int | None:
    """Which of ``shapes`` (a look from aside, `_side_step`) is ``first``'s candidate; the
    outlines are simplified to within ``outline_px``."""
    shape = first.shapes[first.judgement.candidate]
    return same_roof_aside(shape, first.photo, shapes, photo, upper_m, outline_px)


def _look_again(
    m: SearchMission, look: Look, roof_m: float, ceiling_m: float
) -> tuple[Vec3, str] | None:
    """Where to look from again and why, or None when the look was conclusive: a match, no
    candidate, a candidate of another hue, or a clear miss centred in the photo."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or other_outline(j) or j.too_small:
        return None  # drawn too small: from higher it is smaller still
    shape = look.shapes[j.candidate]
    u, v = shape.centroid_px
    k = photo.intrinsics
    off = math.hypot(u - k.cx_px, v - k.cy_px) / (k.height_px / 2.0)
    if not j.judgeable:
        why = "outline cut by the image border"
    elif j.score >= m.params.recognize.threshold:  # unmatched all the same: the mirror rule
        why = f"score {j.score:.3f}, but as much like the target's mirror image"
    elif j.score >= p.recheck_min_score:
        why = f"score {j.score:.3f} just below the threshold"
    elif off > p.recheck_offcentre:
        why = "candidate off the photo's centre"
    else:
        return None
    x, y = ground_point(u, v, photo.pose, photo.intrinsics, plane_z_m=min(roof_m, look.alt_m - 1))
    there = (x, y, min(look.alt_m + p.recheck_climb_m, ceiling_m))
    if math.dist(there, photo.pose.pos_enu_m) <= p.arrive_radius_m:
        return None  # the same photo again: nothing to learn
    return there, why
