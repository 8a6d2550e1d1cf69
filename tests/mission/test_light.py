"""The search in low light: the roof is told from its walls by geometry, and a courtyard
whose floor does not show still tells its building from the target."""

from __future__ import annotations

from pathlib import Path

from uavtool.mission import Status
from uavtool.runner.fly import FlyConfig
from uavtool.runner.fly import fly as fly_scene

DATA = Path(__file__).parent / "data"


def test_a_low_sun_neither_hides_the_target_nor_passes_a_courtyard_decoy_for_it() -> None:
    """Town scene 47037 in any light (`scene random --hard --town --light`): the sun 23.6°
    up from the south-south-east. The target b03 stands on two legs, a plain slab from above;
    b06 is the same slab round a narrow courtyard 25 m deep.

    Taking the roof for the brightest shade of its colour, the looks at b03 kept instead
    the sunlit walls of a neighbour of its colour (brighter than any roof in that light), and
    b06's courtyard, filled by its lit far wall, did not show: b06 was reported as the
    target, completed (score 0.983). Now b03 is found, and b06, whose roof shows an opening
    the target picture does not, is not taken for it."""
    summary = fly_scene(FlyConfig(scene=str(DATA / "light-47037.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b03"
