"""The mission's per-photo vision, as plain functions of (parameters, photo): what the mission
does with each frame, and what replay re-runs on every recorded frame."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.camera import Intrinsics, project
from uavtool.mission.errors import MissionInputError
from uavtool.mission.observations import Photo, U8Array
from uavtool.mission.params import Params
from uavtool.nav import NavError, frame_corners_px, frame_on_plane, ground_point
from uavtool.nav.geometry import point_segment_distance
from uavtool.nav.heights import (
    higher_part_m,
    nadir_px,
    outline_residual_px,
    roof_from_photos,
)
from uavtool.vision import Shape, best_match, mirror_score, vectorize
from uavtool.vision.merge import merge_touching
from uavtool.vision.model3d import central_shape
from uavtool.vision.shapes import perimeter
from uavtool.vision.vectorize import ground_mask, hue_distance_deg, inner_walls
from uavtool.vision.verify import (
    detail_differs,
    hides_detail,
    outline_accuracy_px,
    outline_gap,
    outline_tolerance,
)


def nadir_shapes(params: Params, image_rgb: U8Array) -> tuple[Shape, ...]:
    """Shapes of a photo from above: roofs, with one building's roofs joined."""
    shapes = vectorize(image_rgb, params.vectorize)
    p = params.mission
    return merge_touching(
        shapes, gap_px=p.roof_gap_px, colour_tolerance_dn=p.roof_colour_tolerance_dn
    )


def side_shapes(params: Params, image_rgb: U8Array) -> tuple[Shape, ...]:
    """Shapes of a photo from the side (walls and roofs)."""
    return vectorize(image_rgb, params.side_vectorize)


def target_shapes(params: Params, target_rgb: U8Array) -> tuple[tuple[Shape, ...], Shape]:
    """The target picture's shapes and the target: the largest the picture shows whole (a
    building pictured from above; what runs out of the picture on every side is the ground
    it stands on, of a colour), else the largest."""
    shapes = nadir_shapes(params, target_rgb)
    if not shapes:
        raise MissionInputError("target image: no coloured shape found in it")
    whole = [s for s in shapes if not s.cut_by_border] or list(shapes)
    return shapes, max(whole, key=lambda s: s.area_px)


@dataclass(frozen=True, slots=True)
class Judgement:
    """A nadir photo at a point of interest compared with the target: ``scores`` per shape,
    ``candidate`` the shape the photo is centred on (−1 none), its ``score``, and whether it
    is a match: judgeable, shape score at the threshold, a hue close to the target's (if
    asked), as many courtyards (holes) as the target, more like the target than like the
    target's mirror image (the mirror rule, :class:`uavtool.vision.RecognizeParams`), and its
    outline on the target's (`uavtool.vision.verify`)."""

    scores: tuple[float, ...]
    candidate: int
    score: float
    matched: bool
    judgeable: bool = True
    """False when the candidate's outline is cut by the image border (then never a match)."""
    same_hue: bool = True
    """Whether the candidate's hue is within the hue gate of the target's (True without one)."""
    mirror_score: float = 0.0
    """The candidate's score against the target's mirror image."""
    not_mirror: bool = True
    """Whether the mirror rule holds."""
    outline_gap: float = 0.0
    """How far the candidate's outline lies from the target's, put on it (at unit area:
    :func:`uavtool.vision.verify.outline_gap`); 0 when not measured (no syntactic match)."""
    outline_tolerance: float = 0.0
    """The largest gap two outlines of one footprint show in these two photos."""
    stepped: bool = False
    """The corners matched, but the target picture shows parts of the building at several
    heights (walls inside its roof's outline): each photo's perspective draws them apart by
    its own distance, so the outlines are not compared."""
    too_small: bool = False
    """The candidate is drawn too small to tell the target's corners (not judgeable): at
    its size a quarter of the target's edges would be shorter than the vectorizer keeps an
    edge (``vectorize.min_edge_px``), or its outline leaves out (``Shape.detail_px``) a
    feature the target picture would draw as an edge. A closer look may judge it; a higher
    one cannot."""
    detail_differs: bool = False
    """The outlines lie together, but one photo's outline left out a feature (a notch or a
    cut corner drawn under the least edge kept) that the other photo would draw and does
    not (:func:`uavtool.vision.verify.detail_differs`): another footprint."""
    mirror_image: bool = False
    """The candidate is the target's mirror image, not the target: judgeable, of the
    target's hue, its score against the mirror image at the threshold and above its score
    against the target by the mirror rule's margin and the noise, for a target that differs
    from its own mirror image by more than noise can blur (twice ``mirror_tolerance``: the
    target's and its mirror's scores each within it). The mirror rule turned inside out: the
    target itself loses to its mirror image by no more than noise. A stepped target too: a
    photo's perspective lowers both scores, it does not draw the target mirrored."""

    @property
    def outline_fits(self) -> bool:
        """Whether the outline lies on the target's within the photos' accuracy, and neither
        left out a feature the other does not show."""
        return self.outline_gap <= self.outline_tolerance and not self.detail_differs


def aimed_shape(
    params: Params,
    shapes: tuple[Shape, ...],
    intrinsics: Intrinsics,
    colour_rgb: tuple[int, int, int] | None,
) -> Shape | None:
    """The shape a photo aimed at a building of ``colour_rgb`` (None: of any colour) shows it
    as: the one the photo is centred on among the shapes of that colour (hues no further
    apart than the vectorizer's own tolerance), or among all when none has it. The photo was
    aimed from an estimate; a larger building of another colour beside it may lie nearer
    the centre."""
    if colour_rgb is not None:
        tol = params.vectorize.hue_tolerance_deg
        same = tuple(s for s in shapes if hue_distance_deg(s.colour_rgb, colour_rgb) <= tol)
        if same:
            return central_shape(same, intrinsics)
    return central_shape(shapes, intrinsics)


def stepped(image_rgb: U8Array, shape: Shape, nadir: tuple[float, float] | None = None) -> bool:
    """Whether ``shape`` (a roof in a photo from above) shows walls inside its outline: parts
    of the building at several heights (`inner_walls`; ``nadir``: the photo's point straight
    below the camera, when known)."""
    return bool(inner_walls(image_rgb, shape, nadir_px=nadir))


def shows_higher_part(
    params: Params, image_rgb: U8Array, shape: Shape, nadir: tuple[float, float]
) -> bool:
    """Whether ``shape``'s roof (a photo from above, ``nadir`` its point straight below the
    camera) shows a higher part's walls (`inner_walls`) along at least
    ``vectorize.min_edge_px``, the least length the vectorizer keeps as an edge: a shorter
    strip may be the roof's own outline cutting across one of its outer walls at a corner
    (world 50320: 4.5 px of a near shape's wall, 7.8 px inside its outline, seen from 45 m
    over its roof)."""
    least = params.vectorize.min_edge_px
    return any(
        float(np.hypot(*(strip.max(axis=0) - strip.min(axis=0)))) >= least
        for strip in inner_walls(image_rgb, shape, nadir_px=nadir)
    )


def judge(
    params: Params,
    target: Shape,
    shapes: tuple[Shape, ...],
    intrinsics: Intrinsics,
    aimed_rgb: tuple[int, int, int] | None = None,
    *,
    target_stepped: bool = False,
    chosen: int | None = None,
) -> Judgement:
    """The photo's shapes against the target; the candidate is :func:`aimed_shape`'s (the
    photo was aimed at a building of ``aimed_rgb``, None when not known). A syntactic match
    must also lie on the target's outline (`uavtool.vision.verify`), unless the target
    picture shows parts at several heights (``target_stepped``): each photo's perspective
    then draws them apart by its own distance. ``chosen``: the candidate is that shape
    (found otherwise, `same_roof_aside`), not the one the photo is centred on."""
    centre = (
        shapes[chosen] if chosen is not None else aimed_shape(params, shapes, intrinsics, aimed_rgb)
    )
    candidate = next((i for i, s in enumerate(shapes) if s is centre), -1)
    if centre is None or candidate < 0:
        return Judgement((), -1, 0.0, False)
    _, matches = best_match(target, shapes, params.recognize)
    scores = tuple(match.score for match in matches)
    score = scores[candidate]
    judgeable = matches[candidate].judgeable
    # at the candidate's size, would three quarters of the target's edges be edges at all?
    size = math.sqrt(max(centre.area_px, 0.0))
    least = params.vectorize.min_edge_px
    too_small = judgeable and quartile_edge_share(target) * size < least
    hue_limit = params.mission.match_hue_tolerance_deg
    same_hue = hue_limit <= 0 or hue_distance_deg(centre.colour_rgb, target.colour_rgb) <= hue_limit
    rp = params.recognize
    if judgeable and not too_small and same_hue and not target_stepped and score < rp.threshold:
        # corners under the threshold rule a building of the target's hue out only where
        # every edge of the target would be kept: one edge lost turns the target's own
        # corners into another sequence (world 50076: the target, 16 px across, scored 0).
        # The colour classes' median filter rounds each corner, shortening an edge by up to
        # half its aperture at either end.
        kept = least + max(params.vectorize.denoise_px - 1, 0)
        too_small = edge_share(target, shortest=True) * size < kept
    judgeable = judgeable and not too_small
    mirrored = mirror_score(target, centre, rp)
    gap = 1.0 - mirror_score(target, target, rp)  # how unlike its mirror image the target is
    not_mirror = score - mirrored >= rp.mirror_margin * gap - rp.mirror_tolerance
    mirror_image = (
        judgeable
        and same_hue
        and gap > 2.0 * rp.mirror_tolerance
        and mirrored >= rp.threshold
        and mirrored - score >= rp.mirror_margin * gap + rp.mirror_tolerance
    )
    # courtyards are part of the footprint: one more or fewer than the target picture shows
    # is another building, however well the outer outlines agree
    same_holes = len(centre.holes_px) == len(target.holes_px)
    matched = judgeable and same_hue and not_mirror and same_holes and score >= rp.threshold
    # its corners are the target's, but does its outline leave out (`Shape.detail_px`) what
    # the target picture would draw as an edge? A notch or a cut corner drawn too small to
    # keep may be what makes it another building: not judged from here, a closer look may
    if matched and hides_detail(target, centre, params.vectorize.min_edge_px):
        matched, judgeable, too_small = False, False, True
    outline, tolerance, tiers, differs = 0.0, 0.0, False, False
    if matched:
        # the corners agree; the outline must also lie on the target's: a near shape (a
        # trapezoid, a notched corner, an arm shorter) has the target's corners too
        # a target picture of one roof height is compared with any candidate: one that shows
        # parts at several heights lies off its outline, and is not the target
        tiers = target_stepped
        if not tiers:
            accuracy = outline_accuracy_px(params.vectorize)
            outline = outline_gap(target, centre, matches[candidate])
            tolerance = outline_tolerance(target, centre, accuracy, accuracy)
            differs = detail_differs(target, centre)
            matched = outline <= tolerance and not differs
    return Judgement(
        scores,
        candidate,
        score,
        matched,
        judgeable,
        same_hue,
        mirrored,
        not_mirror,
        outline,
        tolerance,
        tiers,
        too_small,
        differs,
        mirror_image,
    )


def quartile_edge_share(shape: Shape) -> float:
    """The lower quartile of the edges of ``shape``'s outline (holes included) over the
    square root of its area: how long, in pixels, three quarters of its edges at least are
    drawn per pixel of a photo's scale. (Not the shortest: a target picture's outline may
    hold a short edge or two that are no corner of the footprint, a higher tier's walls seen
    in perspective.)"""
    return edge_share(shape, shortest=False)


def edge_share(shape: Shape, *, shortest: bool) -> float:
    """The shortest (or, not ``shortest``, the lower quartile) of the edges of ``shape``'s
    outline, holes included, over the square root of its area."""
    edges = sorted(
        float(e)
        for ring in (shape.polygon_px, *shape.holes_px)
        if len(ring) >= 2
        for e in np.hypot(*np.diff(np.vstack([ring, ring[:1]]), axis=0).T)
    )
    if not edges:
        return 0.0
    edge = edges[0] if shortest else edges[(len(edges) - 1) // 4]
    return edge / math.sqrt(max(shape.area_px, 1.0))


def same_roof_aside(
    shape: Shape,
    photo: Photo,
    shapes: tuple[Shape, ...],
    aside: Photo,
    upper_m: float,
    outline_px: float,
) -> int | None:
    """Which of ``shapes`` (nadir photo ``aside``, taken at ``photo``'s altitude) is the
    roof ``shape`` of ``photo``, whose height is not known but at most ``upper_m``; None
    unless exactly one may be. Seen from one altitude a flat roof is drawn alike whatever
    its height: one whole outline of the same size (within ``outline_px`` all round: how far
    a simplified outline may lie from the roof's edge), and its centroid where ``shape``'s
    lands for a height between 0 and ``upper_m`` (within ``outline_px`` of that stretch).
    The shape nearest the centre may be another."""
    if shape.cut_by_border:
        return None
    k = photo.intrinsics
    u, v = shape.centroid_px
    top = min(upper_m, photo.pose.pos_enu_m[2] - 1.0)
    try:
        ends = [ground_point(u, v, photo.pose, k, plane_z_m=z) for z in (0.0, top)]
    except NavError:
        return None
    lands = project(np.array([[*ends[0], 0.0], [*ends[1], top]]), aside.pose, k)
    a, b = (float(lands[0, 0]), float(lands[0, 1])), (float(lands[1, 0]), float(lands[1, 1]))
    around = perimeter(np.asarray(shape.polygon_px, np.float64))
    alike = [
        i
        for i, s in enumerate(shapes)
        if not s.cut_by_border
        and abs(s.area_px - shape.area_px) <= around * outline_px
        and point_segment_distance(s.centroid_px, a, b) <= outline_px
    ]
    return alike[0] if len(alike) == 1 else None


def placed_roof(a: Shape, photo_a: Photo, b: Shape, photo_b: Photo) -> float | None:
    """The height at which ``a`` (in nadir ``photo_a``) and ``b`` (in ``photo_b``), by their
    centroids and sizes, are one roof, with no check that one flat roof explains their
    outlines (`roof_between` makes it); None when the two views cannot tell."""
    return roof_from_photos(
        centroid1_px=a.centroid_px,
        area1_px=a.area_px,
        pose1=photo_a.pose,
        centroid2_px=b.centroid_px,
        area2_px=b.area_px,
        pose2=photo_b.pose,
        intrinsics=photo_a.intrinsics,
    )


def roof_between(a: Shape, photo_a: Photo, b: Shape, photo_b: Photo) -> float | None:
    """The height above home of one roof seen as ``a`` in ``photo_a`` and ``b`` in
    ``photo_b`` (nadir photos), at least 0; None when either outline is cut by its border or
    the two views cannot tell."""
    if a.cut_by_border or b.cut_by_border:
        return None
    roof = placed_roof(a, photo_a, b, photo_b)
    if roof is None:
        return None
    roof = max(roof, 0.0)
    # One flat roof at that height must explain both outlines: carried from the photo that
    # shows it larger to the other, they agree within ONE_ROOF_PX of the coarser photo.
    fine, coarse = (
        ((a, photo_a), (b, photo_b)) if a.area_px >= b.area_px else ((b, photo_b), (a, photo_a))
    )
    residual = outline_residual_px(
        ring_px=fine[0].polygon_px.tolist(),
        pose=fine[1].pose,
        other_ring_px=coarse[0].polygon_px.tolist(),
        other_pose=coarse[1].pose,
        intrinsics=coarse[1].intrinsics,
        plane_z_m=roof,
    )
    if residual > ONE_ROOF_PX:
        return None
    # ... and nothing inside the outline may stand higher: tiers of one colour show from
    # above only as walls inside the lowest tier's outline.
    flat = not (not_flat(a, photo_a, roof, photo_b, b) or not_flat(b, photo_b, roof, photo_a, a))
    return roof if flat else None


def not_flat(
    shape: Shape,
    photo: Photo,
    roof_m: float,
    other: Photo | None = None,
    other_shape: Shape | None = None,
) -> bool:
    """Whether the walls seen inside ``shape``'s outline (a nadir ``photo``) show a part of
    the building standing at least ``NOT_FLAT_M`` above the roof the outline is at: walls
    whose foot, on their side toward the photo's nadir, is not the ground. A wall
    whose place on the roof ``other`` (another nadir photo) shows as ground, or falls in a
    hole of the roof's outline there (``other_shape``'s courtyards, which show ground
    somewhere), is a courtyard's far wall, going down, not a higher part's: a higher part
    shows from above as its walls on one side and its roof, never as a hole."""
    # Any shade beyond the colour tolerance counts here: a roof taken for flat is flown
    # near, and a tier's walls under much ambient light differ little from its roof (24 DN
    # in world scene 50104, whose 16 m tower was measured at its lowest tier, 6.6 m).
    walls = inner_walls(
        photo.image_rgb,
        shape,
        nadir_px=nadir_px(photo.pose, photo.intrinsics),
        shade_dn=_WALL_SHADE_DN,
    )
    if other is not None and walls:
        ground = ground_mask(other.image_rgb)
        if other_shape is not None and other_shape.holes_px:
            ground = ground.copy()
            for hole in other_shape.holes_px:
                cv2.fillPoly(ground, [np.round(hole).astype(np.int32).reshape(-1, 1, 2)], 255)
        walls = [w for w in walls if not _shows_ground(w, photo, other, roof_m, ground)]
    top = higher_part_m(walls, photo.pose, photo.intrinsics, roof_m=roof_m)
    return top is not None and top > roof_m + NOT_FLAT_M


_WALL_SHADE_DN = 15
"""How far (in some channel) a strip inside a roof must lie from the roof's colour to be a
wall when telling whether the roof is flat: the colour tolerance (`inner_walls`' default
``tolerance_dn``), without the factor of two the look's judgement keeps."""


_GROUND_SHARE = 0.2
"""The share of a wall's pixels that, carried to the other photo on the roof's plane, must
fall on ground for the wall to be a courtyard's."""


def _shows_ground(
    wall_px: npt.NDArray[np.int32], photo: Photo, other: Photo, plane_m: float, ground: U8Array
) -> bool:
    k = photo.intrinsics
    corners = frame_corners_px(k)
    try:
        world = [(x, y, plane_m) for x, y in frame_on_plane(photo.pose, k, plane_z_m=plane_m)]
    except NavError:
        return False
    there = project(np.array(world), other.pose, other.intrinsics)
    if not bool(np.all(there[:, 2] > 0.0)):
        return False
    h = cv2.getPerspectiveTransform(np.array(corners, np.float32), there[:, :2].astype(np.float32))
    uv = cv2.perspectiveTransform(wall_px.reshape(-1, 1, 2).astype(np.float32), h)[:, 0, :]
    u, v = np.round(uv[:, 0]).astype(np.int64), np.round(uv[:, 1]).astype(np.int64)
    seen = (u >= 0) & (u < ground.shape[1]) & (v >= 0) & (v < ground.shape[0])
    if not seen.any():
        return False
    return float((ground[v[seen], u[seen]] > 0).mean()) >= _GROUND_SHARE


NOT_FLAT_M = 3.0
"""How much higher than its outline's height a part of a roof may stand for the roof to
count as flat: half of ``mission.min_above_roof_m``'s default, so a step below it still
leaves half the clearance over the outline's height."""


ONE_ROOF_PX = 1.0
"""How far (RMS, pixels of the coarser photo) two outlines of one roof may lie apart once the
finer is carried to the other photo at the measured height. Outlines are simplified to
``vectorize.rdp_epsilon_px`` (1.5 px), whose error spread evenly has an RMS under 0.9 px; a
blend of heights lies further off. Measured: flat roofs 0.03-0.6 px; tiers 1.5 m apart
0.9 px; tiers 5 m apart 1.2 px; a black 23 m block with its walls 10 px. Above the limit no
height is given (the blend would be lower than the top)."""
