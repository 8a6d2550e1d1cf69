"""The search in low light: the roof is told from its walls by geometry, and a courtyard
whose floor does not show still tells its building from the target."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from uavtool.camera import Intrinsics
from uavtool.mission import Status
from uavtool.runner.fly import FlyConfig, target_picture
from uavtool.runner.fly import fly as fly_scene
from uavtool.world import Lighting, load_scene
from uavtool.world.scene import dump_scene

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


@pytest.mark.parametrize(
    ("flown", "pictured"),
    [
        ((270.0, 12.0, 0.25), (150.0, 88.0, 0.6)),  # at dusk from the west, pictured at noon
        ((150.0, 88.0, 0.6), (270.0, 12.0, 0.25)),  # and the other way round
        ((40.0, 5.0, 0.15), (200.0, 60.0, 0.8)),  # 5° up in the north-east, little sky light
    ],
)
def test_the_target_picture_may_be_taken_in_another_light(
    tmp_path: Path, flown: tuple[float, float, float], pictured: tuple[float, float, float]
) -> None:
    """The paper scene flown in one light, its target picture rendered in another: colour is
    compared by hue, which the light does not change, and shape by the roof's outline."""
    paper = load_scene("paper")
    scene = tmp_path / "flown.yaml"
    scene.write_text(dump_scene(dataclasses.replace(paper, lighting=Lighting(*flown))))
    target = tmp_path / "target.png"
    target.write_bytes(
        target_picture(
            dataclasses.replace(paper, lighting=Lighting(*pictured)), Intrinsics.from_hfov()
        )
    )
    summary = fly_scene(FlyConfig(scene=str(scene), target=target, no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "red"
