"""The lowest a look may descend to over a point: above every known roof near it by the
safety margin, and no lower than the ceiling near a roof of unknown height."""

from __future__ import annotations

import numpy as np

from uavtool.mission import MissionInputs, Params, SearchMission
from uavtool.mission.unknown import Unknown


def _mission() -> SearchMission:
    target = np.full((120, 160, 3), 128, np.uint8)
    target[40:80, 50:110] = (210, 40, 40)
    return SearchMission(Params(), MissionInputs(target))


def test_floor_over_tiers_and_unknown_roofs() -> None:
    m = _mission()
    square = ((0.0, 0.0), (6.0, 0.0), (6.0, 6.0), (0.0, 6.0))
    inner = ((2.0, 2.0), (4.0, 2.0), (4.0, 4.0), (2.0, 4.0))
    m.roofs = ((square, 20.0), (inner, 43.0))  # two tiers of one tower, measured apart
    margin = m.params.viewpoints.safety_margin_m + m.params.mission.arrive_radius_m
    assert m.floor_at(3.0, 3.0) == 43.0 + margin  # over the top tier
    assert m.floor_at(0.5, 0.5) == 43.0 + margin  # over the lower tier, 1.5 m from the top
    assert m.floor_at(-5.0, -5.0) == 0.0  # 7 m from either: nothing to clear
    m.ceiling_m = 117.4
    where = ((20.0, 0.0), (26.0, 0.0), (26.0, 6.0), (20.0, 6.0))
    m.unknown = {3: Unknown(where, 115.0)}  # nothing rules out a roof up to just below the ceiling
    assert m.floor_at(18.0, 3.0) == 117.4  # within the margin of it: the ceiling, no higher
    assert m.floor_at(9.0, 3.0) == 20.0 + margin  # 3 m from the lower tier, 5 m from the top
    m.unknown = {3: Unknown(where, 30.0)}  # the ground seen around it rules out more than 30 m
    assert m.floor_at(18.0, 3.0) == 30.0 + margin
    # where it stands for each range of heights: 9 m off, only the lowest reach
    higher = ((25.0, 0.0), (31.0, 0.0), (31.0, 6.0), (25.0, 6.0))
    m.unknown = {3: Unknown(where, 30.0, ((where, 12.0), (higher, 30.0)))}
    assert m.floor_at(17.0, 3.0) == 12.0 + margin
    assert m.floor_at(33.0, 3.0) == 30.0 + margin
    m.learn_roof(3, where, 8.0)  # a closer look measured it
    assert m.floor_at(18.0, 3.0) == 8.0 + margin
