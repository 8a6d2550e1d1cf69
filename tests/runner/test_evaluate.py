"""The summary's label of the matched building: found by the overlap of footprints, so an L,
a U or a courtyard whose corners average to a point inside a neighbour is still itself."""

from __future__ import annotations

from typing import Any

import pytest

from uavtool.runner.evaluate import building_under, nearest_building
from uavtool.world import scene_from_dict

L = [[0, 0], [20, 0], [20, 4], [4, 4], [4, 20], [0, 20]]
U = [[0, 0], [20, 0], [20, 16], [16, 16], [16, 4], [4, 4], [4, 16], [0, 16]]
# a courtyard building as the scene file spells one: four wings around an open yard
COURTYARD_WINGS = [
    [[0, 0], [20, 0], [20, 4], [0, 4]],
    [[16, 4], [20, 4], [20, 16], [16, 16]],
    [[0, 16], [20, 16], [20, 20], [0, 20]],
    [[0, 4], [4, 4], [4, 16], [0, 16]],
]
COURTYARD_OUTLINE = [[0, 0], [20, 0], [20, 20], [0, 20]]  # as measured from above


def _scene(target: list[list[list[float]]], neighbour: list[list[float]]) -> Any:
    def block(fp: list[list[float]]) -> dict[str, Any]:
        return {"footprint": fp, "top_m": 6}

    return scene_from_dict(
        {
            "target": "target",
            "buildings": [
                {"name": "target", "color": [210, 40, 40], "blocks": [block(f) for f in target]},
                {"name": "neighbour", "color": [40, 90, 220], "blocks": [block(neighbour)]},
            ],
        }
    )


def _average(ring: list[list[float]]) -> tuple[float, float]:
    return sum(p[0] for p in ring) / len(ring), sum(p[1] for p in ring) / len(ring)


@pytest.mark.parametrize(
    ("target", "measured", "neighbour"),
    [
        ([L], L, [[6, 6], [10, 6], [10, 10], [6, 10]]),  # in the L's inner corner
        ([U], U, [[6, 8], [14, 8], [14, 14], [6, 14]]),  # between the U's arms
        (COURTYARD_WINGS, COURTYARD_OUTLINE, [[7, 7], [13, 7], [13, 13], [7, 13]]),  # in the yard
    ],
    ids=["L", "U", "courtyard"],
)
def test_the_matched_footprint_is_the_building_it_overlaps(
    target: list[list[list[float]]], measured: list[list[float]], neighbour: list[list[float]]
) -> None:
    scene = _scene(target, neighbour)
    # the average of the corners lies in the neighbour: labelling by it says WRONG
    assert nearest_building(scene, _average(measured)) == "neighbour"
    ring = [(x + 0.4, y - 0.3) for x, y in measured]  # measured, a little off
    assert building_under(scene, ring) == "target"


def test_a_footprint_over_no_building_is_the_nearest_one() -> None:
    scene = _scene([L], [[30, 30], [34, 30], [34, 34], [30, 34]])
    assert building_under(scene, [(40, 40), (44, 40), (44, 44), (40, 44)]) == "neighbour"
