"""The mirror rule: a candidate matches only if it is more like the target than like the
target's mirror image, by a margin. Drawn outlines, every rotation and several scales."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uavtool.camera import Intrinsics
from uavtool.mission import Params
from uavtool.mission.analysis import Judgement, judge, nadir_shapes, target_shapes
from uavtool.world.raster import paint_polygon

K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
RGB = (200, 40, 40)
# Chiral outlines (unlike their mirror images), in metres-like units around the origin.
L_SHAPE = [(0, 0), (10, 0), (10, 4), (4, 4), (4, 14), (0, 14)]
STEP = [(0, 0), (12, 0), (12, 5), (7, 5), (7, 9), (3, 9), (3, 12), (0, 12)]
FLAG = [(0, 0), (3, 0), (3, 6), (10, 9), (3, 12), (3, 14), (0, 14)]
RECT = [(0, 0), (12, 0), (12, 7), (0, 7)]  # its own mirror image


def _draw(ring: list[tuple[int, int]], *, turn_deg: float, px_per_unit: float, mirror: bool):
    pts = np.array(ring, dtype=np.float64)
    pts -= pts.mean(axis=0)
    if mirror:
        pts[:, 0] = -pts[:, 0]
    a = math.radians(turn_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    pts = pts @ rot.T * px_per_unit + np.array([320.0, 240.0])
    image = np.full((480, 640, 3), 128, dtype=np.uint8)
    paint_polygon(image, pts, RGB)
    return image


def _judge(ring: list[tuple[int, int]], **pose: float | bool) -> Judgement:
    params = Params()
    _, target = target_shapes(params, _draw(ring, turn_deg=0.0, px_per_unit=14.0, mirror=False))
    shapes = nadir_shapes(params, _draw(ring, **pose))  # type: ignore[arg-type]
    return judge(params, target, shapes, K)


def _decide(ring: list[tuple[int, int]], **pose: float | bool) -> tuple[bool, float, float]:
    j = _judge(ring, **pose)
    return j.matched, j.score, j.mirror_score


TURNS = range(0, 360, 30)
SCALES = (9.0, 14.0, 20.0)


@pytest.mark.parametrize("ring", [L_SHAPE, STEP, FLAG], ids=["L", "step", "flag"])
@pytest.mark.parametrize("px_per_unit", SCALES)
def test_a_mirror_image_never_matches(ring: list[tuple[int, int]], px_per_unit: float) -> None:
    for turn in TURNS:
        matched, score, mirrored = _decide(
            ring, turn_deg=turn, px_per_unit=px_per_unit, mirror=True
        )
        assert not matched, (turn, score, mirrored)


@pytest.mark.parametrize("ring", [L_SHAPE, STEP, FLAG, RECT], ids=["L", "step", "flag", "rect"])
@pytest.mark.parametrize("px_per_unit", SCALES)
def test_a_turned_and_scaled_copy_always_matches(
    ring: list[tuple[int, int]], px_per_unit: float
) -> None:
    for turn in TURNS:
        matched, score, mirrored = _decide(
            ring, turn_deg=turn, px_per_unit=px_per_unit, mirror=False
        )
        assert matched, (turn, score, mirrored)


def test_a_symmetric_target_matches_its_mirror_image() -> None:
    """A rectangle is its own mirror image: the rule does not apply."""
    matched, _, _ = _decide(RECT, turn_deg=40.0, px_per_unit=14.0, mirror=True)
    assert matched


@pytest.mark.parametrize("ring", [L_SHAPE, STEP, FLAG], ids=["L", "step", "flag"])
@pytest.mark.parametrize("px_per_unit", SCALES)
def test_a_mirror_image_is_told_apart_and_the_target_never_is(
    ring: list[tuple[int, int]], px_per_unit: float
) -> None:
    """Scoring its mirror image well and clearly better than the target, a building is the
    target's mirror image: another building, not a doubt (the search does not wait on it).
    The target itself, turned and scaled, never is."""
    for turn in TURNS:
        j = _judge(ring, turn_deg=turn, px_per_unit=px_per_unit, mirror=True)
        assert j.mirror_image, (turn, j.score, j.mirror_score)
        j = _judge(ring, turn_deg=turn, px_per_unit=px_per_unit, mirror=False)
        assert not j.mirror_image, (turn, j.score, j.mirror_score)


def test_a_symmetric_targets_mirror_image_is_no_other_building() -> None:
    for turn in TURNS:
        assert not _judge(RECT, turn_deg=turn, px_per_unit=14.0, mirror=True).mirror_image
