"""Tower targets of the town scenes whose height the overviews could not tell: measured
before their side photos are planned, so the side photos hold the whole height (issue 26)."""

from __future__ import annotations

from pathlib import Path

import pytest

from uavtool.mission import Status
from uavtool.recording import LogEntry, RecordingReader
from uavtool.recording.topics import EVENTS
from uavtool.runner.fly import FlyConfig, fly

DATA = Path(__file__).parent / "data"


def _events(path: Path) -> list[str]:
    with RecordingReader(path) as reader:
        return [e.value.message for e in reader.entries([EVENTS]) if isinstance(e.value, LogEntry)]


def test_a_courtyard_tower_cut_by_the_overview_is_measured_and_modelled() -> None:
    """Town scene 10245: the target, a 48.9 m courtyard L, is cut by the overview's border,
    its courtyard cut open with it. Its height was never measured (the cut outline's
    courtyard edges fit no height of the whole outline), so its side views were planned
    for 25 m and cut its top. The whole outline's edges on the cut one's measure it, and
    the model is built."""
    summary = fly(FlyConfig(scene=str(DATA / "town-10245.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b05"
    assert summary.evaluation.model_iou is not None and summary.evaluation.model_iou > 0.8


def test_a_tower_looked_at_from_the_ceiling_is_measured_by_its_top_photo(tmp_path: Path) -> None:
    """Town scene 10264: the target, a 58.8 m courtyard L among towers as tall, is cut by
    the overview's border and looked at from the ceiling, with no room for a photo from
    another altitude. The look and the top photo see it whole from two places 10 m apart:
    they measure it, and the side photos planned for that height build the model (planned
    for the assumed 25 m, every one cut its top)."""
    record = tmp_path / "f.mcap"
    summary = fly(FlyConfig(scene=str(DATA / "town-10264.yaml"), record=record))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b05"
    assert summary.evaluation.model_iou is not None and summary.evaluation.model_iou > 0.8
    said = [e for e in _events(record) if "the look and the top photo measure" in e]
    assert len(said) == 1
    assert float(said[0].split("roof ")[1].split(" m")[0]) == pytest.approx(58.8, abs=1.0)


def test_a_tower_merged_with_one_of_its_colour_behind_it_is_whole_in_the_side_photo() -> None:
    """Town scene 3387: the target, a 55.2 m courtyard L, stands in front of a tower of its
    colour. In the front photo the two merge, and the one behind rises out of the frame.
    Cut back to the box where the target stands (its height measured), the silhouette kept
    a tenth more than the box and so reached the frame: taken for a cut top, the camera
    backed away until the target's own top left the frame, and no model was built."""
    summary = fly(FlyConfig(scene=str(DATA / "town-3387.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b12"
    assert summary.evaluation.model_iou is not None and summary.evaluation.model_iou > 0.8


def test_a_courtyard_tower_is_measured_though_one_photo_sees_no_courtyard_floor() -> None:
    """Town scene 3519: the target, a 50.2 m courtyard rectangle, looked at from the ceiling
    shows its courtyard's far walls but no floor; the top photo shows the courtyard as a
    hole. The walls were taken for a taller part standing on the roof, so the two photos
    gave no height, and side photos planned for 25 m never held the tower. A wall that
    falls in a hole of the other photo's outline goes down: the roof is measured."""
    summary = fly(FlyConfig(scene=str(DATA / "town-3519.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b01"
    assert summary.evaluation.model_iou is not None and summary.evaluation.model_iou > 0.8


def test_a_tier_whose_walls_differ_little_from_its_roof_keeps_the_roof_unmeasured() -> None:
    """World scene 50104: the target is a tower of three tiers (6.6, 12.3 and 16 m) in one
    green, under much ambient light (0.76): its tiers' walls differ from the roof by 24 DN,
    under the twice-the-tolerance (30 DN) a look's judgement asks of a wall. The tour then
    took its outline's height, the lowest tier's 6.6 m, for a flat roof, and after the match
    the mission descended to 15.4 m over it: into the top tier (a crash, reported as one).
    Telling whether a roof is flat, any shade beyond the tolerance is a wall."""
    summary = fly(FlyConfig(scene=str(DATA / "world-50104.yaml"), no_record=True))
    assert summary.outcome.status is not Status.CRASHED, summary.outcome.reason
    assert summary.clearance_m is not None and summary.clearance_m > 2.0
