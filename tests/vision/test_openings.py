"""`enclosed_openings`: what shows inside a roof's outline besides the roof."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest

from uavtool.vision import vectorize
from uavtool.vision.vectorize import enclosed_openings

GROUND = (128, 128, 128)
ROOF = (140, 205, 50)
WALL = (92, 136, 34)


def _roof(
    *, opening: tuple[int, int, int, int] | None = None, notch: bool = False
) -> npt.NDArray[np.uint8]:
    image = np.full((240, 320, 3), GROUND, np.uint8)
    image[60:180, 80:240] = ROOF
    if notch:  # a U: the notch open to the ground at the top, its walls beside it
        image[60:120, 140:180] = GROUND
        image[60:120, 140:146] = WALL
    if opening is not None:
        v0, v1, u0, u1 = opening
        image[v0:v1, u0:u1] = WALL
        image[v0 : v0 + 2, u1 - 3 : u1] = GROUND  # a sliver of the floor
    return image


def _count(image: npt.NDArray[np.uint8]) -> int:
    (shape,) = vectorize(image)
    assert not shape.holes_px  # walls and a sliver of ground: no hole for the vectorizer
    return enclosed_openings(image, shape, least_px=30)


def test_a_plain_roof_and_a_u_show_no_opening() -> None:
    assert _count(_roof()) == 0
    assert _count(_roof(notch=True)) == 0


@pytest.mark.parametrize("where", [(130, 150, 100, 120), (150, 170, 200, 225)])
def test_a_courtyard_whose_floor_does_not_show_is_one_opening(
    where: tuple[int, int, int, int],
) -> None:
    assert _count(_roof(opening=where)) == 1


def test_an_opening_smaller_than_the_least_is_none() -> None:
    assert _count(_roof(opening=(130, 134, 100, 105))) == 0
