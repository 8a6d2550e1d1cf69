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
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import cv2
import numpy as np
import shapely

from uavtool.camera import Intrinsics
from uavtool.mission.analysis import (
    ONE_ROOF_PX,
    Judgement,
    aimed_shape,
    judge,
    nadir_shapes,
    not_flat,
    quartile_edge_share,
    roof_between,
    same_roof_aside,
    shows_higher_part,
    side_shapes,
)
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest, Recognition, Shapes, Status, Vec3
from uavtool.mission.unknown import shows_as
from uavtool.nav import NavError, ground_point, ground_polygon, visit_order
from uavtool.nav.geometry import point_polygon_distance
from uavtool.nav.heights import fit_altitude_m, nadir_px
from uavtool.nav.parallax import roof_by_alignment
from uavtool.vision import Shape, best_match
from uavtool.vision.shapes import perimeter
from uavtool.vision.vectorize import (
    enclosed_openings,
    hue_distance_deg,
    outline_mask,
    same_paint,
)
from uavtool.vision.verify import carried_point, outline_accuracy_px

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


@dataclass(frozen=True, slots=True)
class Found:
    """The matched point of interest, the photo that matched and the matched shape in it."""

    poi: PointOfInterest
    photo: Photo
    shape: Shape
    score: float
    roof_m: float
    """The roof's height, measured again from the look (closer, so more precise) when it
    could be, else the point of interest's."""
    roof_measured: bool = False
    """Whether ``roof_m`` was measured (else it is the height assumed)."""
    outline_compared: bool = True
    """Whether the match's outline was compared with the target's (not when the target
    picture shows parts at several heights: `Judgement.stepped`)."""


@dataclass(frozen=True, slots=True)
class _Look:
    photo: Photo
    shapes: tuple[Shape, ...]
    judgement: Judgement
    alt_m: float  # the altitude commanded for the photo


Look = _Look
"""One look at a point of interest: its photo, the shapes in it and their judgement."""


def photo_shapes(
    m: SearchMission,
    photo: Photo,
    *,
    nadir: bool = True,
    keep: Callable[[Shape, tuple[Shape, ...]], bool] | None = None,
) -> tuple[Shape, ...]:
    """Vectorize a photo (from above, or from the side) and emit its shapes (those ``keep``
    keeps, if given: it is given each shape and all the photo's)."""
    if nadir:
        shapes = nadir_shapes(m.params, photo.image_rgb)
    else:
        shapes = side_shapes(m.params, photo.image_rgb)
    if keep is not None:
        every = shapes
        shapes = tuple(s for s in every if keep(s, every))
    m.emit(Shapes(photo.frame_index, photo.tag, shapes))
    return shapes


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
    unjudged: list[tuple[int, _Look]] = []  # of the target's hue, never judged
    doubtful: list[tuple[int, _Look, bool]] = []  # of the target's hue, judged in doubt
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
            best = _found(poi, look, roof)
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
            matches.append(_found(poi, look, roof))
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
        doubts = yield from _doubts_by_tiers(m, best, doubts, pois)
    _judged_all(m, best, doubts)
    best = yield from _settle(m, best, matches)
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


Inspection = tuple[list["_Look"], float | None]
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
    looks = [(yield from _look(m, k, 1, alt, poi.colour_rgb))]
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
                yield from _shift(m, aside, f"point of interest {k}, look {n}")
                same = functools.partial(
                    _same_aside, looks[-1], still.upper_m, m.params.vectorize.rdp_epsilon_px
                )
                looks.append((yield from _look(m, k, n, aside[2], poi.colour_rgb, same)))
                continue
        if step is not None and still is not None:
            m.event(
                Level.INFO,
                f"point of interest {k}: drawn too small to judge; its roof not measured (at "
                f"most {still.upper_m:.1f} m above home): looking again from straight above "
                f"it, at {step[2]:.1f} m",
            )
            yield from m.travel(step, None, transit_m, f"point of interest {k}, look {n}")
            looks.append((yield from _look(m, k, n, step[2], poi.colour_rgb)))
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
            looks.append((yield from _look(m, k, n, pos[2], poi.colour_rgb)))
            continue
        again = _look_again(m, looks[-1], roof_m, ceiling_m)
        if again is None:
            break
        pos, why = again
        m.event(
            Level.INFO,
            f"point of interest {k}: {why}; looking again from above its roof at {pos[2]:.1f} m",
        )
        yield from _shift(m, pos, f"point of interest {k}, look {n}")
        looks.append((yield from _look(m, k, n, pos[2], poi.colour_rgb)))
    return looks, upper


def _left_unjudged(looks: list[_Look]) -> _Look | None:
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


def _doubtful(m: SearchMission, looks: list[_Look]) -> tuple[_Look, bool] | None:
    """The look that left a point of interest in doubt, if the looks did, and whether the
    doubt is its walls: a candidate of the target's hue that no look matched, and either

    - scored between ``mission.recheck_min_score`` and the threshold, none of its outlines
      told apart from the target's (`_other_outline`): the looks asked to see it again,
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
    apart = [look for look in judged if _other_outline(look.judgement)]
    if apart:
        if all(_walls_inside(m, look) for look in apart):
            return max(apart, key=lambda look: look.judgement.score), True
        return None  # a near shape, told apart clearly
    doubts = [look for look in judged if least <= look.judgement.score < threshold]
    if not doubts:
        return None
    return max(doubts, key=lambda look: look.judgement.score), False


def _walls_inside(m: SearchMission, look: _Look) -> bool:
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


def _judged_all(m: SearchMission, best: Found, unjudged: list[tuple[int, _Look]]) -> None:
    """End the mission NO_MATCH when a building of the target's hue other than ``best``'s
    was never judged (drawn too small to tell its outline, or cut by the border, however
    it was looked at): it may be the target, and ``best`` a building almost like it."""
    for k, look in unjudged:
        shape = look.shapes[look.judgement.candidate]
        if k == best.poi.index or _on_roof(best, look.photo, shape):
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
    if _other_outline(j):
        return f"its outline, {j.outline_gap * 100:.1f} % off, may hold its own walls"
    return f"scored {j.score:.3f} from too far to tell, and could not be looked at closer"


def _found(poi: PointOfInterest, look: _Look, roof_m: float | None) -> Found:
    """The match of ``look`` at ``poi``, its roof at ``roof_m`` when measured (else the point
    of interest's)."""
    j = look.judgement
    return Found(
        poi,
        look.photo,
        look.shapes[j.candidate],
        j.score,
        poi.roof_m if roof_m is None else roof_m,
        roof_m is not None or poi.roof_measured,
        not j.stepped,
    )


def _settle(m: SearchMission, best: Found, matches: list[Found]) -> Wait[Found]:
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


def _doubts_by_tiers(
    m: SearchMission,
    best: Found,
    doubts: list[tuple[int, _Look]],
    pois: tuple[PointOfInterest, ...],
) -> Wait[list[tuple[int, _Look]]]:
    """The buildings of the target's hue left in doubt (``doubts``: scored under the
    threshold from too far to tell, their outlines not compared) that may still be the
    target, when the target picture shows a higher part's walls and ``best``'s roof shows
    one: not those whose roof, photographed as the picture was, shows none (`_by_tiers`)."""
    if not (yield from _higher_part(m, best, [best])):
        return doubts
    left = []
    for k, look in doubts:
        f = _found(pois[k], look, None)
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
    size needs (`_resolving_altitude_m`): were ``f`` the target, the camera would stand as
    far above each of its parts as the picture's did. None when no such photo can be taken
    (the floor over roofs of unknown height, the ceiling), it does not show the roof whole,
    or it shows no higher part but draws the roof smaller than the picture draws the target
    (the way there may have held it higher): then it says nothing."""
    p = m.params
    photo, k = f.photo, f.photo.intrinsics
    _, matches = best_match(m.target, (f.shape,), p.recognize)
    at = carried_point(m.target, f.shape, matches[0], m.target_nadir_px)
    alt_was = photo.pose.pos_enu_m[2]
    plane = min(f.roof_m, alt_was - 1.0)
    if at is None:
        return None
    try:
        x, y = ground_point(*at, photo.pose, k, plane_z_m=plane)
        ring = ground_polygon(f.shape.polygon_px, photo.pose, k, plane_z_m=plane)
    except NavError:
        return None
    as_large = _resolving_altitude_m(m, f.shape, alt_was, plane, ring, (x, y), k)
    whole = _whole_altitude_m(m, plane, ring, (x, y), k)
    alt = max(min(alt_was, as_large), whole, plane + p.mission.min_above_roof_m, m.floor_at(x, y))
    if m.ceiling_m is not None and alt > m.ceiling_m:
        return None
    others = ", ".join(str(o.poi.index) for o in left if o is not f)
    what = (
        f"point of interest {f.poi.index}: over where the target picture was taken from, "
        f"to tell it from {others} by a higher part"
    )
    yield from _shift(m, (x, y, alt), what)
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
    if 2.0 * drawn - _less_accuracy(shape, off) < _less_accuracy(m.target, off):
        return None
    return False


def _inside_roof(f: Found, photo: Photo, shape: Shape) -> bool:
    """Whether a point inside ``shape`` (in ``photo``), on ``f``'s roof's plane, lies on
    that roof: `_on_roof` with a point the outline holds, where an L's centroid may fall
    in its notch."""
    u, v = shapely.Polygon(shape.polygon_px).representative_point().coords[0]
    inside = replace(shape, centroid_px=(float(u), float(v)))
    return _on_roof(f, photo, inside)


def _less_accuracy(shape: Shape, off_px: float) -> float:
    """``shape``'s size (``sqrt(area_px)``) less its outline's pixel accuracy all round:
    the least its footprint may be drawn."""
    drawn = math.sqrt(max(shape.area_px, 1.0))
    return max(drawn - perimeter(shape.polygon_px) * off_px / (2.0 * drawn), 1.0)


def _rivals_of(m: SearchMission, best: Found, matches: list[Found]) -> list[Found]:
    """The other buildings that matched and nothing yet tells from ``best``: not ``best``'s
    own roof seen again, and showing as many courtyards as the target picture if ``best``
    does — and, unless the target picture shows parts at several heights (whose walls each
    photo's perspective shows or hides), as many openings inside the roof (a courtyard whose
    floor does not show: `enclosed_openings`)."""
    holes = len(m.target.holes_px)
    rivals = []
    for f in matches:
        if f.poi.index == best.poi.index or _on_roof(best, f.photo, f.shape):
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
    extent = math.dist(*_farthest_pair(ring))
    fit = fit_altitude_m(roof_m=f.roof_m, extent_m=extent, intrinsics=k, fill=p.top_fill)
    lower = max(fit, f.roof_m + p.min_above_roof_m)
    clear = alt_was - p.recheck_climb_m / 2.0
    if lower <= clear < m.floor_at(x, y):  # held up by roofs of unknown height: the look
        m.measure_near(x, y, photo, photo_shapes(m, photo))  # that matched may measure them
    alt = max(lower, m.floor_at(x, y))
    if alt > clear:
        return None
    others = ", ".join(str(o.poi.index) for o in left if o is not f)
    yield from _shift(
        m, (x, y, alt), f"point of interest {poi.index}: closer, to tell it from {others}"
    )
    look = yield from _look(m, poi.index, p.max_looks + 1, alt, poi.colour_rgb)
    return look.judgement


def _shows_again(best: Found, look: _Look) -> bool:
    """Whether a look's matched candidate is the building already matched (``best``): its
    centre, on the matched roof's plane, lies on that roof. A look aimed at a rival of the
    target's hue (walls whose roof the overview did not show) may find the matched
    building nearer its centre; that is no new evidence."""
    return _on_roof(best, look.photo, look.shapes[look.judgement.candidate])


def _on_roof(best: Found, photo: Photo, shape: Shape) -> bool:
    """Whether ``shape``'s centre (in ``photo``), on the matched roof's plane, lies on that
    roof."""
    plane_m = min(best.roof_m, best.photo.pose.pos_enu_m[2] - 1.0, photo.pose.pos_enu_m[2] - 1.0)
    try:
        ring = ground_polygon(
            best.shape.polygon_px, best.photo.pose, best.photo.intrinsics, plane_z_m=plane_m
        )
        here = ground_point(*shape.centroid_px, photo.pose, photo.intrinsics, plane_z_m=plane_m)
    except NavError:
        return False
    return point_polygon_distance(here, ring) == 0.0


def _beats(m: SearchMission, k: int, look: _Look, best: Found) -> bool:
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


def of_target_hue(m: SearchMission, rgb: tuple[int, int, int]) -> bool:
    """Whether a building of colour ``rgb`` may be the target: its hue within
    ``mission.match_hue_tolerance_deg`` of the target picture's (any, when that is 0)."""
    limit = m.params.mission.match_hue_tolerance_deg
    return limit <= 0 or hue_distance_deg(rgb, m.target.colour_rgb) <= limit


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
    m: SearchMission, k: int, poi: PointOfInterest, look: _Look, shape: Shape
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


def _look(
    m: SearchMission,
    k: int,
    n: int,
    alt_m: float,
    aimed_rgb: tuple[int, int, int],
    find: Callable[[tuple[Shape, ...], Photo], int | None] | None = None,
) -> Wait[_Look]:
    """Look ``n`` at point of interest ``k`` (a building of colour ``aimed_rgb``): a nadir
    photo, judged and reported. ``find``: a look to measure the roof of a building drawn too
    small to judge (`_side_step`), which shape is that building (None: not told apart). Drawn
    as small again, it is not judged here (a borderline outline may pass from one photo and
    not from the other), only measured."""
    photo = yield from m.photo(f"poi-{k}" if n == 1 else f"poi-{k}-{n}", -90.0)
    shapes = photo_shapes(m, photo)
    chosen = None if find is None else find(shapes, photo)
    if find is not None and chosen is None:
        j = Judgement((), -1, 0.0, False)
        m.emit(Recognition(photo.frame_index, k, (), -1, 0.0, False, 0.0))
        m.event(
            Level.INFO,
            f"point of interest {k}, look {n}: the building not told apart from others here",
        )
        return _Look(photo, shapes, j, alt_m)
    j = judge(
        m.params,
        m.target,
        shapes,
        photo.intrinsics,
        aimed_rgb,
        target_stepped=m.target_stepped,
        chosen=chosen,
    )
    if find is not None:  # as small as the look that could not judge it: to measure only
        j = replace(j, matched=False, judgeable=False, too_small=True, mirror_image=False)
    m.emit(
        Recognition(photo.frame_index, k, j.scores, j.candidate, j.score, j.matched, j.mirror_score)
    )
    why = ""
    if find is not None:
        why = "; from aside to measure its roof, drawn as small: not judged"
    elif j.too_small:
        why = "; drawn too small here to tell the target's outline, not judged"
    elif not j.judgeable:
        why = "; outline cut by the image border, not judged"
    elif j.mirror_image:
        why = f"; the target's mirror image, scored {j.mirror_score:.3f}: another building"
    elif not j.not_mirror and j.score >= m.params.recognize.threshold:
        why = f"; as much like the target's mirror image: {j.mirror_score:.3f}"
    elif j.stepped:
        why = "; parts at several heights: outline not compared"
    elif j.outline_tolerance > 0.0:
        fits = "within" if j.outline_gap <= j.outline_tolerance else "beyond"
        why = (
            f"; outline {j.outline_gap * 100:.1f} % of its size off the target's, {fits} "
            f"the photos' {j.outline_tolerance * 100:.1f} %"
        )
        if j.detail_differs:
            why += ", but one photo's outline leaves out a corner the other does not show"
    m.event(
        Level.INFO,
        f"point of interest {k}{'' if n == 1 else f', look {n}'}: "
        f"{'MATCH' if j.matched else 'no match'} (score {j.score:.3f}{why})",
    )
    return _Look(photo, shapes, j, alt_m)


def _closer_look(
    m: SearchMission,
    look: _Look,
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
    judging it needs (`_resolving_altitude_m`). None when that is not clearly lower (by
    half ``recheck_climb_m``) or the height cannot be told."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or _other_outline(j):
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
    extent = math.dist(*_farthest_pair(ring))
    u, v = shape.centroid_px
    x, y = ground_point(u, v, photo.pose, k, plane_z_m=plane)
    fit = fit_altitude_m(roof_m=roof, extent_m=extent, intrinsics=k, fill=p.look_fill)
    if j.too_small:
        fit = min(fit, _resolving_altitude_m(m, shape, alt, roof, ring, (x, y), k))
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


def _step_down(m: SearchMission, look: _Look, upper_m: float) -> Vec3 | None:
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
    span_px = math.dist(*_farthest_pair(tuple(map(tuple, shape.polygon_px))))
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


def _side_step(m: SearchMission, look: _Look) -> Vec3 | None:
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
    first: _Look, upper_m: float, outline_px: float, shapes: tuple[Shape, ...], photo: Photo
) -> int | None:
    """Which of ``shapes`` (a look from aside, `_side_step`) is ``first``'s candidate; the
    outlines are simplified to within ``outline_px``."""
    shape = first.shapes[first.judgement.candidate]
    return same_roof_aside(shape, first.photo, shapes, photo, upper_m, outline_px)


def _resolving_altitude_m(
    m: SearchMission,
    shape: Shape,
    alt_m: float,
    roof_m: float,
    ring: tuple[tuple[float, float], ...],
    aim: tuple[float, float],
    k: Intrinsics,
) -> float:
    """The altitude at which ``shape`` (drawn too small to judge from ``alt_m``, its roof at
    ``roof_m``) is drawn as large as the target picture draws the target: then its outline
    leaves out nothing the target picture shows (`hides_detail`), and the target's edges are
    edges at its size (`quartile_edge_share`). Never closer than where a photo aimed at
    ``aim`` (its centroid on its roof) holds every corner of its outline (``ring``, on the
    ground) with the arrival radius to spare on the photo's shorter side: a fill fraction
    (``mission.top_fill``, for a model's top photo) would keep a building drawn a few per
    cent smaller than the target picture from ever being judged (world 50072: the closest
    look it allowed drew a notched near shape at 97 % of the picture's scale)."""
    p = m.params
    need_px = max(
        math.sqrt(max(m.target.area_px, 0.0)),
        p.vectorize.min_edge_px / max(quartile_edge_share(m.target), 1e-9),
    )
    # as large at the least: its outline is known to the pixel grid's accuracy all round
    # (world 50072: aimed at the picture's scale by its drawing, a look drew it at 99.6 %
    # of it). Not to what it left out: a stepped building's tiers, drawn apart, would send
    # the look so close that perspective draws them further apart still (hard scene 89)
    least_px = _less_accuracy(shape, outline_accuracy_px(p.vectorize))
    resolving = roof_m + (alt_m - roof_m) * least_px / need_px
    return max(resolving, _whole_altitude_m(m, roof_m, ring, aim, k))


def _whole_altitude_m(
    m: SearchMission,
    roof_m: float,
    ring: tuple[tuple[float, float], ...],
    aim: tuple[float, float],
    k: Intrinsics,
) -> float:
    """The lowest altitude from which a photo straight down over ``aim`` holds every corner
    of ``ring`` (a roof's outline at ``roof_m``, on the ground) with the arrival radius to
    spare on the photo's shorter side."""
    reach = max((math.dist(aim, corner) for corner in ring), default=0.0)
    return fit_altitude_m(
        roof_m=roof_m,
        extent_m=2.0 * (reach + m.params.mission.arrive_radius_m),
        intrinsics=k,
        fill=1.0,
    )


def _other_outline(j: Judgement) -> bool:
    """Whether the look was conclusive all the same: the candidate's corners are the
    target's, but its outline lies further from the target's than the two photos' accuracy
    allows (a near shape). Another look, higher or closer, measures the same footprint."""
    return j.outline_tolerance > 0.0 and not j.outline_fits


def _farthest_pair(
    ring: tuple[tuple[float, float], ...],
) -> tuple[tuple[float, float], tuple[float, float]]:
    return max(
        ((a, b) for i, a in enumerate(ring) for b in ring[i + 1 :]),
        key=lambda ab: math.dist(*ab),
        default=((0.0, 0.0), (0.0, 0.0)),
    )


def _shift(m: SearchMission, pos: Vec3, what: str) -> Wait[None]:
    """A move to ``pos`` at its altitude (a look's re-centring, a closer look), no lower
    than the altitude that clears every roof, known or not, there and along the way (the
    look's own altitude was cleared only where it was taken); straight up first when that
    is above the vehicle."""
    here = m.last.pos_enu_m if m.last is not None else pos
    x, y, z = pos
    # the whole way, not only where it ends: a closer look at a rival may lie across the
    # scene (world 50193: 64 m at 16.6 m, through a 22.5 m roof the mission had measured)
    need = m.floor_along((here[0], here[1]), (x, y))
    z = max(z, need)
    if need > here[2]:
        yield from m.move((here[0], here[1], z), None, f"{what}: up to {z:.1f} m")
    yield from m.move((x, y, z), None, what)


def _look_again(
    m: SearchMission, look: _Look, roof_m: float, ceiling_m: float
) -> tuple[Vec3, str] | None:
    """Where to look from again and why, or None when the look was conclusive: a match, no
    candidate, a candidate of another hue, or a clear miss centred in the photo."""
    p = m.params.mission
    j, photo = look.judgement, look.photo
    if j.matched or j.candidate < 0 or not j.same_hue or _other_outline(j) or j.too_small:
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
