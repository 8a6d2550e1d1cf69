"""A look at a building and what it is made of: the photo's shapes, its judgement against the
target, the move to where it is taken and the altitudes it may be taken from. The search
(`uavtool.mission.search`) takes looks at each point of interest; when several buildings
match, `uavtool.mission.settle` takes more to tell them apart."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from uavtool.camera import Intrinsics
from uavtool.mission.analysis import (
    Judgement,
    judge,
    nadir_shapes,
    quartile_edge_share,
    side_shapes,
)
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level, PointOfInterest, Recognition, Shapes, Vec3
from uavtool.nav import NavError, ground_point, ground_polygon
from uavtool.nav.geometry import point_polygon_distance
from uavtool.nav.heights import fit_altitude_m
from uavtool.vision import Shape
from uavtool.vision.shapes import perimeter
from uavtool.vision.vectorize import hue_distance_deg
from uavtool.vision.verify import outline_accuracy_px

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
class Look:
    """One look at a point of interest: its photo, the shapes in it and their judgement."""

    photo: Photo
    shapes: tuple[Shape, ...]
    judgement: Judgement
    alt_m: float  # the altitude commanded for the photo


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


def found(poi: PointOfInterest, look: Look, roof_m: float | None) -> Found:
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


def less_accuracy(shape: Shape, off_px: float) -> float:
    """``shape``'s size (``sqrt(area_px)``) less its outline's pixel accuracy all round:
    the least its footprint may be drawn."""
    drawn = math.sqrt(max(shape.area_px, 1.0))
    return max(drawn - perimeter(shape.polygon_px) * off_px / (2.0 * drawn), 1.0)


def on_roof(best: Found, photo: Photo, shape: Shape) -> bool:
    """Whether ``shape``'s centre (in ``photo``), on the matched roof's plane, lies on that
    roof."""
    return point_on_roof(best, photo, shape.centroid_px)


def point_on_roof(best: Found, photo: Photo, point_px: tuple[float, float]) -> bool:
    """Whether ``point_px`` (in ``photo``), on the matched roof's plane, lies on that roof."""
    plane_m = min(best.roof_m, best.photo.pose.pos_enu_m[2] - 1.0, photo.pose.pos_enu_m[2] - 1.0)
    try:
        ring = ground_polygon(
            best.shape.polygon_px, best.photo.pose, best.photo.intrinsics, plane_z_m=plane_m
        )
        here = ground_point(*point_px, photo.pose, photo.intrinsics, plane_z_m=plane_m)
    except NavError:
        return False
    return point_polygon_distance(here, ring) == 0.0


def of_target_hue(m: SearchMission, rgb: tuple[int, int, int]) -> bool:
    """Whether a building of colour ``rgb`` may be the target: its hue within
    ``mission.match_hue_tolerance_deg`` of the target picture's (any, when that is 0)."""
    limit = m.params.mission.match_hue_tolerance_deg
    return limit <= 0 or hue_distance_deg(rgb, m.target.colour_rgb) <= limit


def take_look(
    m: SearchMission,
    k: int,
    n: int,
    alt_m: float,
    aimed_rgb: tuple[int, int, int],
    find: Callable[[tuple[Shape, ...], Photo], int | None] | None = None,
) -> Wait[Look]:
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
        return Look(photo, shapes, j, alt_m)
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
    return Look(photo, shapes, j, alt_m)


def resolving_altitude_m(
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
    least_px = less_accuracy(shape, outline_accuracy_px(p.vectorize))
    resolving = roof_m + (alt_m - roof_m) * least_px / need_px
    return max(resolving, whole_altitude_m(m, roof_m, ring, aim, k))


def whole_altitude_m(
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


def other_outline(j: Judgement) -> bool:
    """Whether the look was conclusive all the same: the candidate's corners are the
    target's, but its outline lies further from the target's than the two photos' accuracy
    allows (a near shape). Another look, higher or closer, measures the same footprint."""
    return j.outline_tolerance > 0.0 and not j.outline_fits


def farthest_pair(
    ring: tuple[tuple[float, float], ...],
) -> tuple[tuple[float, float], tuple[float, float]]:
    return max(
        ((a, b) for i, a in enumerate(ring) for b in ring[i + 1 :]),
        key=lambda ab: math.dist(*ab),
        default=((0.0, 0.0), (0.0, 0.0)),
    )


def shift(m: SearchMission, pos: Vec3, what: str) -> Wait[None]:
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
