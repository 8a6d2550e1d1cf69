"""Ground or not, by parallax between two photos from above (`uavtool.nav.parallax`): a
flat area of any colour is ground, a roof of the same colour and outline is not, and near
the point below both cameras the photos cannot tell."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.nav.parallax import PARALLAX_PX, on_ground, plane_homography, roof_by_alignment
from uavtool.world import Block, Building, load_scene, render
from uavtool.world.ground import GroundArea, GroundTexture, TextureKind
from uavtool.world.scene import Lighting

K = Intrinsics.from_hfov(width_px=640, height_px=480)
LOW = CameraPose((0.0, 0.0, 45.0), 0.0, -90.0)
HIGH = CameraPose((0.0, 0.0, 117.0), 0.0, -90.0)
BESIDE = CameraPose((-30.0, 20.0, 117.0), 0.0, -90.0)
"""As the mission's roof measurement tour takes its photos: at the overview's height, over
another building."""
GREEN = (60, 160, 60)
SQUARE = ((0.0, 0.0), (8.0, 0.0), (8.0, 6.0), (0.0, 6.0))


def _at(x: float, y: float) -> tuple[tuple[float, float], ...]:
    return tuple((px + x, py + y) for px, py in SQUARE)


def _photos(
    lawn_at: tuple[float, float], roof_at: tuple[float, float], roof_m: float, other: CameraPose
) -> tuple[np.ndarray, np.ndarray]:
    """A green lawn and a green box of the lawn's outline, ``roof_m`` tall, on grey ground;
    photographed from ``other`` and HIGH."""
    box = Building("box", GREEN, (Block(_at(*roof_at), 0.0, roof_m),))
    scene = dataclasses.replace(
        load_scene("paper"),
        buildings=(box,),
        target="box",
        ground_areas=(GroundArea("lawn", GREEN, _at(*lawn_at)),),
    )
    return render(scene, other, K), render(scene, HIGH, K)


def _region(ring: tuple[tuple[float, float], ...], z: float) -> np.ndarray:
    px = project(np.array([(x, y, z) for x, y in ring]), HIGH, K)[:, :2]
    mask = np.zeros((K.height_px, K.width_px), np.uint8)
    cv2.fillPoly(mask, [np.round(px).astype(np.int32)], 255)
    return mask


def _ground(mask: np.ndarray, other: np.ndarray, high: np.ndarray, pose: CameraPose) -> bool | None:
    return on_ground(mask, GREEN, high, HIGH, other, pose, K, top_m=44.0, least_px=60.0)


@pytest.mark.parametrize("roof_m", [3.0, 6.0, 15.0])
def test_a_lawn_is_ground_and_a_roof_of_its_colour_and_outline_is_not(roof_m: float) -> None:
    lawn, roof = (-22.0, 4.0), (14.0, -12.0)
    beside, high = _photos(lawn, roof, roof_m, BESIDE)
    assert _ground(_region(_at(*lawn), 0.0), beside, high, BESIDE) is True
    assert _ground(_region(_at(*roof), roof_m), beside, high, BESIDE) is False


def test_under_the_cameras_the_photos_cannot_tell() -> None:
    """Straight below both cameras no height moves anything."""
    low, high = _photos((-4.0, -3.0), (30.0, 20.0), 6.0, LOW)
    assert _ground(_region(_at(-4.0, -3.0), 0.0), low, high, LOW) is None


def test_a_height_the_other_photo_cannot_show_is_not_ruled_out() -> None:
    """The lower overview sees a plane high up only near the point below it: away from it,
    a roof there is not ruled out, so nothing away from it is called ground by that photo
    alone (a 15 m tower whose roof it does not show once was)."""
    low, high = _photos((-22.0, 4.0), (30.0, 20.0), 6.0, LOW)
    assert _ground(_region(_at(-22.0, 4.0), 0.0), low, high, LOW) is None


TEAL = (39, 115, 114)


def _field(texture: GroundTexture | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A teal ground as wide as the frame, with towers 12-30 m tall standing on it near
    home, photographed from LOW and HIGH; and the ground's pixels in HIGH's photo."""
    towers = tuple(
        Building(f"t{i}", colour, (Block(_at(x, y), 0.0, top),))
        for i, (x, y, top, colour) in enumerate(
            [
                (-14.0, 6.0, 30.0, (200, 60, 60)),
                (8.0, 10.0, 22.0, (60, 60, 200)),
                (-6.0, -16.0, 12.0, (220, 200, 40)),
                (12.0, -8.0, 26.0, (150, 60, 190)),
            ]
        )
    )
    scene = dataclasses.replace(
        load_scene("paper"),
        buildings=towers,
        target="t0",
        ground_rgb=TEAL,
        ground_texture=texture,
    )
    low, high = render(scene, LOW, K), render(scene, HIGH, K)
    near = np.all(np.abs(high.astype(np.int16) - TEAL) <= 30, axis=2)
    return low, high, near.astype(np.uint8) * 255


def _field_ground(texture: GroundTexture | None) -> bool | None:
    low, high, region = _field(texture)
    return on_ground(region, TEAL, high, HIGH, low, LOW, K, top_m=44.0, least_px=60.0)


def test_a_textured_ground_as_wide_as_the_frame_is_ground_by_its_grain() -> None:
    """A ground of a colour fills the frame: it has no edge of its own to line up, and the
    towers standing on it, each at its own height, weigh more on the average misfit than
    the ground's height does. Its grain lines up at the ground only: that tells."""
    grain = GroundTexture(TextureKind.NOISE, 10.0, 2.0, 11)
    assert _field_ground(grain) is True


def test_a_ground_as_wide_as_the_frame_without_grain_is_not_called_ground() -> None:
    """The same field in one flat colour: nothing in it lines up at one height rather than
    another (the towers only misalign it), so no answer is ground."""
    assert _field_ground(None) is not True


def test_the_ground_plane_maps_a_ground_point_to_itself() -> None:
    hom = plane_homography(LOW, HIGH, K, 0.0)
    point = np.array([(12.0, -7.0, 0.0)])
    here = project(point, LOW, K)[0, :2]
    there = cv2.perspectiveTransform(here.reshape(1, 1, 2), hom)[0, 0]
    assert np.allclose(there, project(point, HIGH, K)[0, :2], atol=1e-6)


AHEAD = CameraPose((8.0, 0.0, 117.0), 0.0, -90.0)
"""A photo from beside HIGH, at its altitude: as a look from aside measures a small roof."""
TINY = ((0.0, 0.0), (2.0, 0.0), (2.0, 2.5), (0.0, 2.5))


def _tiny_tower(top_m: float, light: Lighting | None = None) -> tuple[np.ndarray, ...]:
    """A green tower 2 x 2.5 m, ``top_m`` tall, among a few others, photographed from HIGH
    and AHEAD; and its roof's pixels in HIGH's photo and in AHEAD's."""
    ring = tuple((x + 24.0, y + 10.0) for x, y in TINY)
    tower = Building("tiny", GREEN, (Block(ring, 0.0, top_m),))
    others = tuple(
        Building(f"o{i}", colour, (Block(_at(x, y), 0.0, top),))
        for i, (x, y, top, colour) in enumerate(
            [(-14.0, 6.0, 30.0, (200, 60, 60)), (8.0, 22.0, 8.0, (60, 60, 200))]
        )
    )
    base = load_scene("paper")
    scene = dataclasses.replace(
        base, buildings=(tower, *others), target="tiny", lighting=light or base.lighting
    )
    high, ahead = render(scene, HIGH, K), render(scene, AHEAD, K)
    roofs = []
    for pose in (HIGH, AHEAD):
        px = project(np.array([(x, y, top_m) for x, y in ring]), pose, K)[:, :2]
        mask = np.zeros((K.height_px, K.width_px), np.uint8)
        cv2.fillPoly(mask, [np.round(px).astype(np.int32)], 255)
        roofs.append(mask)
    return high, ahead, roofs[0], roofs[1]


@pytest.mark.parametrize("top_m", [4.0, 12.0, 20.0, 35.0])
def test_a_roof_drawn_too_small_to_place_is_measured_by_lining_the_photos_up(top_m: float) -> None:
    """A roof a dozen pixels across: its outline's corners and centroid are a pixel or two
    off, its height by them many metres. Lined up plane by plane, every pixel tells: the
    answer errs high, never low, and by less than the height two pixels' shift between
    the photos stands for there (a plane ``dz`` higher shifts by ``f b dz / (H - z)²``)."""
    high, ahead, here, there = _tiny_tower(top_m)
    for args in ((here, high, HIGH, ahead, AHEAD), (there, ahead, AHEAD, high, HIGH)):
        region, image, pose, other, other_pose = args
        roof = roof_by_alignment(
            region, GREEN, image, pose, other, other_pose, K, top_m=100.0, least_px=20.0
        )
        assert roof is not None
        two_px = PARALLAX_PX * (HIGH.pos_enu_m[2] - top_m) ** 2 / (K.fx_px * 8.0)
        assert top_m <= roof < top_m + two_px


def test_a_roof_whose_walls_share_its_shade_is_measured_on_the_safe_side() -> None:
    """The sun 45° up in the south: the tower's south wall is drawn in its roof's very
    shade, so the region may hold it, and a plane a little lower lines up almost as well.
    The answer is then higher than the roof, not lower."""
    light = Lighting(sun_azimuth_deg=180.0, sun_elevation_deg=45.0, ambient=0.5)
    high, ahead, here, _ = _tiny_tower(20.0, light)
    walls = cv2.dilate(here, np.ones((5, 5), np.uint8))  # the roof and what is drawn beside
    roof = roof_by_alignment(walls, GREEN, high, HIGH, ahead, AHEAD, K, top_m=100.0, least_px=20.0)
    assert roof is not None
    assert roof >= 20.0


def test_a_roof_the_other_photo_cannot_show_above_is_not_measured() -> None:
    """Swept up to where the other photo no longer shows the region, a roof as high as the
    sweep reaches is not told from what may stand higher still."""
    high, ahead, here, _ = _tiny_tower(20.0)
    assert (
        roof_by_alignment(here, GREEN, high, HIGH, ahead, AHEAD, K, top_m=20.5, least_px=20.0)
        is None
    )
