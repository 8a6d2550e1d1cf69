"""What the overviews show that lies on the ground: lawns, roads, car parks, fields, the
ground itself in a colour. Not buildings, not points of interest, not obstacles — told by
parallax between two photos (`uavtool.nav.parallax`), not by colour or how common it is."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.camera import project
from uavtool.mission.observations import Photo
from uavtool.nav.parallax import STOREY_M, least_telling_m, on_ground, stands_out
from uavtool.vision import Shape
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import (
    is_grey,
    near_colour,
    non_ground,
    not_ground_regions,
    outline_mask,
    same_paint,
)

if TYPE_CHECKING:
    from uavtool.mission.mission import SearchMission

CvArray = Any
_WALL_BAND_PX = 3
"""How far around a region its walls are looked for: past its blended edge."""
_SHADES = 4
"""How many shades of what looks like walls beside a region are told apart (`_painted`)."""
_HIDDEN_PX = 2
"""How far around a known building's drawing the ground is taken for hidden: the blended
edge of its outline."""
_NEAR_DN = 30
"""A region is one colour when all but a shape's worth of its pixels lie this close (per
channel) to its colour: flat shading and a ground texture (`uavtool.nav.parallax`)."""


def lies_on_ground(
    m: SearchMission,
    shape: Shape,
    photo: Photo,
    others: Sequence[Photo],
    *,
    one_colour: bool,
    beside: Sequence[Shape] = (),
    unanimous: bool = False,
    hidden: Sequence[CvArray] | None = None,
) -> bool:
    """Whether ``shape`` (in nadir ``photo``) is ground, by parallax against one of
    ``others`` (nadir photos from elsewhere): False when none can tell. With ``unanimous``,
    also when one of them tells it stands. ``hidden``: per photo of ``others``, where it
    shows what hides the ground (left out). With ``one_colour``
    (a region of everything that is not ground, which may join a building and a road it
    touches), only a region of one colour may be: else what it holds besides might stand.
    ``beside``: the roofs ``photo`` shows (its shapes), whose own roofs and walls are not
    this region's walls (`wall_pixels`)."""
    if not others:
        return False
    least = m.params.vectorize.min_area_px
    walls = wall_pixels(photo, shape, shape.colour_rgb, beside)
    if _count(walls) >= m.params.vectorize.min_edge_px and not _painted(
        walls, photo, others, least, m.params.vectorize.min_edge_px, unanimous, hidden
    ):
        return False
    region = outline_mask(photo.image_rgb, shape)
    if one_colour:
        other_colour = cv2.bitwise_and(region, cv2.bitwise_not(_near(photo, shape.colour_rgb)))
        if cv2.countNonZero(other_colour) >= least:
            return False
    return _flat(region, shape.colour_rgb, photo, others, least, unanimous, hidden)


def _flat(
    region: CvArray,
    colour_rgb: tuple[int, int, int],
    photo: Photo,
    others: Sequence[Photo],
    least_px: float,
    unanimous: bool = False,
    hidden: Sequence[CvArray] | None = None,
) -> bool:
    """Whether one of ``others`` tells ``region`` (of ``colour_rgb``) lies on the ground
    (and, ``unanimous``, none tells it stands; ``hidden``: as for `lies_on_ground`)."""
    verdicts = (
        on_ground(
            region,
            colour_rgb,
            photo.image_rgb,
            photo.pose,
            other.image_rgb,
            other.pose,
            photo.intrinsics,
            top_m=other.pose.pos_enu_m[2] - 1.0,
            least_px=least_px,
            hidden=None if hidden is None else hidden[i],
        )
        for i, other in enumerate(others)
    )
    if not unanimous:
        return any(v is True for v in verdicts)
    told = {v for v in verdicts if v is not None}
    return told == {True}


def _painted(
    walls: npt.NDArray[np.bool_],
    photo: Photo,
    others: Sequence[Photo],
    least_px: float,
    few_px: float,
    unanimous: bool = False,
    hidden: Sequence[CvArray] | None = None,
) -> bool:
    """Whether what looks like walls beside a region (``walls``) is ground of a shade of
    its colour: a field or a lawn. Shade by shade (the median of what is left), the pixels
    of that shade joined to them must lie on the ground by parallax, as the region itself
    must; a real wall, whose top stands off the ground, does not. At most ``_SHADES``
    shades, until fewer than ``few_px`` are left."""
    left = walls.copy()
    for _ in range(_SHADES):
        if _count(left) < few_px:
            return True
        shade = _median_shade(photo, left)
        near = _near(photo, shade)
        _, labels = cv2.connectedComponents(near, connectivity=8)
        # (np.unique would import numpy.ma: tests/test_imports.py)
        hits = np.bincount(labels[left & (near > 0)], minlength=int(labels.max()) + 1)
        hits[0] = 0
        if not hits.any():
            return False
        joined = (hits > 0)[labels]
        joined_mask = np.where(joined, 255, 0).astype(np.uint8)
        if not _flat(joined_mask, shade, photo, others, least_px, unanimous, hidden):
            return False
        left &= ~joined
    return _count(left) < few_px


def _median_shade(photo: Photo, mask: npt.NDArray[np.bool_]) -> tuple[int, int, int]:
    """The median colour, channel by channel, of ``photo``'s pixels under ``mask``."""
    pixels = np.sort(photo.image_rgb[mask], axis=0)  # (np.median imports numpy.ma)
    r, g, b = (int(c) for c in pixels[len(pixels) // 2])
    return r, g, b


def _count(mask: npt.NDArray[np.bool_]) -> int:
    return int(np.count_nonzero(mask))


def measured_flat(
    shape: Shape,
    photo: Photo,
    other: Photo,
    roof_m: float,
    *,
    least_px: float,
    beside: Sequence[Shape] = (),
) -> bool:
    """Whether a roof measured ``roof_m`` above home from ``photo`` and ``other`` lies lower
    than those two photos tell from the ground there (and they tell a storey, `STOREY_M`),
    and shows no walls (`shows_walls`, at least ``least_px`` pixels of them): a lawn, a
    painted area, measured like a roof, is ground. ``beside``: as for `wall_pixels`."""
    region = outline_mask(photo.image_rgb, shape)
    if shows_walls(photo, shape, shape.colour_rgb, least_px=least_px, beside=beside):
        return False
    least = least_telling_m(
        region,
        photo.pose,
        other.pose,
        photo.intrinsics,
        other.pose.pos_enu_m[2] - 1.0,
    )
    return least is not None and least <= STOREY_M and roof_m < least


def shows_walls(
    photo: Photo,
    shape: Shape,
    colour_rgb: tuple[int, int, int],
    *,
    least_px: float,
    beside: Sequence[Shape] = (),
) -> bool:
    """Whether at least ``least_px`` pixels just outside ``shape``'s outer outline (in
    ``photo``) show another shade of its colour: a building's walls, which perspective shows
    beside its roof (unless it stands straight below the camera). What lies on the ground has
    none; a lawn beside a building of its hue seems to, and is not taken for ground. Inside
    its holes stands whatever they hold: a courtyard's walls, or a building standing on a
    lawn or a ground of its hue, whose walls are its own."""
    return _count(wall_pixels(photo, shape, colour_rgb, beside)) >= least_px


def wall_pixels(
    photo: Photo,
    shape: Shape,
    colour_rgb: tuple[int, int, int],
    beside: Sequence[Shape] = (),
) -> npt.NDArray[np.bool_]:
    """The pixels just outside ``shape``'s outer outline that show another shade of
    ``colour_rgb`` (`shows_walls`), but for those joined, through shades of that paint, to
    another of ``beside`` (the roofs the photo shows): that roof and its walls, not
    ``shape``'s. A lawn at the foot of a building of its hue, or around a brighter roof of
    its hue, was never ground so."""
    outer = _outlines(photo, (shape,))
    kernel = np.ones((2 * _WALL_BAND_PX + 1, 2 * _WALL_BAND_PX + 1), np.uint8)
    band = cv2.subtract(cv2.dilate(outer, kernel), outer)
    shades = same_paint(photo.image_rgb, colour_rgb) & (_near(photo, colour_rgb) == 0)
    walls: npt.NDArray[np.bool_] = (band > 0) & shades
    others = [b for b in beside if b is not shape]
    if others and walls.any():
        _, labels = cv2.connectedComponents(shades.astype(np.uint8), connectivity=8)
        theirs = np.zeros(int(labels.max()) + 1, bool)
        theirs[labels[shades & (_outlines(photo, others) > 0)]] = True
        theirs[0] = False
        walls &= ~theirs[labels]
    return walls


def without_ground(
    m: SearchMission, regions: list[Shape], photo: Photo, others: Sequence[Photo]
) -> tuple[list[Shape], int]:
    """``regions`` (of nadir ``photo``, not ground by colour) with what lies on the ground
    taken out, and how many were ground: a region whose own colour parallax against one of
    ``others`` shows on the ground has that colour's pixels cut from it, and what is left —
    a building standing on a lawn — is kept as the roofs `non_ground` finds in it."""
    least = m.params.vectorize.min_area_px
    kept: list[Shape] = []
    flat = 0
    for r in regions:
        if not lies_on_ground(m, r, photo, others, one_colour=False):
            kept.append(r)
            continue
        flat += 1
        rest = cv2.bitwise_and(
            outline_mask(photo.image_rgb, r), cv2.bitwise_not(_near(photo, r.colour_rgb))
        )
        if cv2.countNonZero(rest) >= least:
            kept.extend(non_ground(photo.image_rgb, m.params.vectorize, within=rest))
    return kept, flat


def regions_off_ground(
    m: SearchMission,
    photo: Photo,
    regions: tuple[Shape, ...],
    ground: Sequence[Shape],
    others: Sequence[Photo] = (),
    known: Sequence[tuple[Sequence[tuple[float, float]], float]] = (),
) -> tuple[Shape, ...]:
    """``regions`` (what is not ground in nadir ``photo`` by its colour) without the pixels
    of ``ground`` (shapes of ``photo`` that lie on the ground by parallax) in their own
    colour: a lawn a building stands on is no part of that building, and a building of
    unknown height may stand anywhere in its region. What stands on them, of another
    colour, stays. With ``others`` (nadir photos from elsewhere), what is left is told
    colour by colour as `standing_regions` tells it (``known``: the roofs measured): a road
    joining a building to the frame's border once made the building's region one cut by
    the frame, which may hold a roof as high as anything (world 50063)."""
    if not ground and not others:
        return regions
    keep: CvArray = np.full(photo.image_rgb.shape[:2], 255, np.uint8)
    for shape in ground:
        flat = cv2.bitwise_and(outline_mask(photo.image_rgb, shape), _near(photo, shape.colour_rgb))
        keep = cv2.bitwise_and(keep, cv2.bitwise_not(flat))
    return _standing(m, photo, keep, others, known)


def standing_regions(
    m: SearchMission,
    photo: Photo,
    others: Sequence[Photo],
    known: Sequence[tuple[Sequence[tuple[float, float]], float]] = (),
) -> tuple[Shape, ...]:
    """What is not ground in nadir ``photo`` by its colour (`not_ground_regions`), without
    what parallax against one of ``others`` (nadir photos from elsewhere) shows lies on the
    ground: a road or a lawn beyond the overview's frame, which a look down from the ceiling
    once took for a building beside every place it looked at. A region of several colours
    (a road joining a field and a building) is told colour by colour, each part of one
    colour on its own, and only where no photo tells it, or a patch of it, stands
    (`_clears`): what such a look clears is cleared for every way through its frame.
    What stands, and whatever else a part's outline holds, is kept. ``known``: the roofs
    measured (footprint, height above home): the ground they hide in ``others`` tells
    nothing, and in ``photo`` they always stand."""
    return _standing(m, photo, None, others, known)


def _standing(
    m: SearchMission,
    photo: Photo,
    within: CvArray | None,
    others: Sequence[Photo],
    known: Sequence[tuple[Sequence[tuple[float, float]], float]],
) -> tuple[Shape, ...]:
    """`standing_regions` of the pixels of ``photo`` in ``within`` (None: all of them)."""
    p = m.params.vectorize
    regions = not_ground_regions(photo.image_rgb, p, within=within)
    if not others:
        return regions
    grow = np.ones((2 * _HIDDEN_PX + 1, 2 * _HIDDEN_PX + 1), np.uint8)
    hidden = [cv2.dilate(_prisms(other, known), grow) for other in others]
    paints = _Paints(photo, others, p, grow)
    keep: CvArray = np.full(photo.image_rgb.shape[:2], 255, np.uint8)
    cut = False
    for region in regions:
        if region.area_px < p.min_area_px:
            continue
        left = outline_mask(photo.image_rgb, region) > 0
        if within is not None:
            left &= within > 0
        for _ in range(_SHADES):
            if _count(left) < p.min_area_px:
                break
            shade = _median_shade(photo, left)
            part = np.where(left & (_near(photo, shade) > 0), 255, 0).astype(np.uint8)
            for piece in not_ground_regions(photo.image_rgb, p, within=part):
                if piece.area_px < p.min_area_px:
                    continue
                behind = [
                    cv2.bitwise_or(h, paints.other_than(i, piece.colour_rgb))
                    for i, h in enumerate(hidden)
                ]
                if _clears(m, piece, photo, others, behind):
                    flat = cv2.bitwise_and(outline_mask(photo.image_rgb, piece), part)
                    keep = cv2.bitwise_and(keep, cv2.bitwise_not(flat))
                    cut = True
            left &= part == 0
    if not cut:
        return regions
    keep = cv2.bitwise_or(keep, _prisms(photo, known))
    if within is not None:
        keep = cv2.bitwise_and(keep, within)
    return not_ground_regions(photo.image_rgb, p, within=keep)


class _Paints:
    """Where each of ``others`` draws the paint (any shade: `same_paint`) of a roof
    ``photo`` shows (`non_ground`), grown by ``grow``: a building leaning over a road in
    another photo from above, its roof and walls drawn where the road lies carried as the
    ground, hides the road there and tells nothing of it (world 50063: a tower beside a
    road, of unknown height, kept the road standing and the tower's region cut by the
    frame). Greys are left out: their paint is every unpainted surface's, the ground's
    too."""

    def __init__(
        self, photo: Photo, others: Sequence[Photo], params: VectorizeParams, grow: CvArray
    ) -> None:
        self._others = others
        self._grow = grow
        roofs = {s.colour_rgb for s in non_ground(photo.image_rgb, params)}
        self._colours = sorted(c for c in roofs if not is_grey(c))
        self._masks: dict[tuple[int, tuple[int, int, int]], CvArray] = {}

    def other_than(self, index: int, rgb: tuple[int, int, int]) -> CvArray:
        """A mask (uint8) of ``others[index]``: where it draws the paint of a roof other
        than ``rgb``'s."""
        image = self._others[index].image_rgb
        mask: CvArray = np.zeros(image.shape[:2], np.uint8)
        swatch = np.full((3, 3, 3), rgb, np.uint8)  # same_paint takes a frame
        for colour in self._colours:
            if bool(same_paint(swatch, colour)[0, 0]):
                continue  # its own paint: what it shows of it is evidence
            key = (index, colour)
            if key not in self._masks:
                drawn = same_paint(image, colour).astype(np.uint8) * 255
                self._masks[key] = cv2.dilate(drawn, self._grow)
            mask = cv2.bitwise_or(mask, self._masks[key])
        return mask


def _prisms(photo: Photo, known: Sequence[tuple[Sequence[tuple[float, float]], float]]) -> CvArray:
    """A mask of ``photo`` (uint8), 255 where it draws one of the ``known`` buildings
    (footprint, roof height): its roof, its base and every wall between them."""
    mask: CvArray = np.zeros(photo.image_rgb.shape[:2], np.uint8)
    for footprint, roof_m in known:
        ring = list(footprint)
        if len(ring) < 3:
            continue
        points = np.array([(x, y, z) for z in (0.0, roof_m) for x, y in ring])
        uv = project(points, photo.pose, photo.intrinsics)
        if (uv[:, 2] <= 0.0).any():
            continue  # not below the camera: a photo from above shows it otherwise
        px = np.round(uv[:, :2]).astype(np.int32)
        n = len(ring)
        faces = [px[:n], px[n:]]
        faces += [px[[i, (i + 1) % n, n + (i + 1) % n, n + i]] for i in range(n)]
        for face in faces:  # one at a time: together, fillPoly would leave overlaps out
            cv2.fillPoly(mask, [face.reshape(-1, 1, 2)], 255)
    return mask


def _clears(
    m: SearchMission,
    piece: Shape,
    photo: Photo,
    others: Sequence[Photo],
    hidden: Sequence[CvArray],
) -> bool:
    """Whether ``piece`` (of one colour, in nadir ``photo``) lies on the ground as a whole:
    one of ``others`` tells it does, none tells it stands (`lies_on_ground`), and in none
    does a patch of it stand out (`stands_out`: what stands on it, joined to it in
    ``photo``) where that photo shows the ground (not ``hidden``: behind known roofs)."""
    if not lies_on_ground(m, piece, photo, others, one_colour=False, unanimous=True, hidden=hidden):
        return False
    region = outline_mask(photo.image_rgb, piece)
    return not any(
        stands_out(
            region,
            piece.colour_rgb,
            photo.image_rgb,
            photo.pose,
            other.image_rgb,
            other.pose,
            photo.intrinsics,
            least_px=m.params.vectorize.min_area_px,
            hidden=behind,
        )
        for other, behind in zip(others, hidden, strict=True)
    )


def _outlines(photo: Photo, shapes: Sequence[Shape]) -> CvArray:
    """A mask of ``photo`` (uint8), 255 inside any of ``shapes``' outer outlines."""
    mask = np.zeros(photo.image_rgb.shape[:2], np.uint8)
    for s in shapes:  # one at a time: together, fillPoly would leave their overlaps out
        cv2.fillPoly(mask, [np.round(s.polygon_px).astype(np.int32).reshape(-1, 1, 2)], 255)
    return mask


def _near(photo: Photo, rgb: tuple[int, int, int]) -> CvArray:
    return near_colour(photo.image_rgb, rgb, _NEAR_DN)
