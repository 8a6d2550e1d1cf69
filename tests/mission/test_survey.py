"""Roofs measured from the tour above the points of interest, before any is flown near
(issue 26)."""

from __future__ import annotations

from pathlib import Path

import pytest

from uavtool.mission import Status
from uavtool.recording import LogEntry, RecordingReader
from uavtool.recording.topics import EVENTS
from uavtool.runner.fly import FlyConfig, fly

DATA = Path(__file__).parent / "data"


def test_a_roof_the_overview_shows_in_part_is_measured_by_two_tour_photos(
    tmp_path: Path,
) -> None:
    """Town scene 11096: the target, a 12.9 m T, stands beside a 54 m tower whose walls, in
    the overview, lean over part of its outline. No one flat roof then explained the
    overview's outline and a tour photo's (1.15 px apart, over the 1.0 px limit), so its
    roof stayed unknown: the target was looked at from over the highest it might be
    (114.8 m) and scored 0.763 there, under the wing decoy's 0.779 from a proper look, and
    the decoy won. Two tour photos agree on its roof (0.06 px): it is looked at from its own
    altitude, scores 0.999 and wins."""
    record = tmp_path / "f.mcap"
    summary = fly(FlyConfig(scene=str(DATA / "town-11096.yaml"), record=record))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b06"
    assert summary.outcome.match_score > 0.95
    with RecordingReader(record) as reader:
        said = [
            e.value.message
            for e in reader.entries([EVENTS])
            if isinstance(e.value, LogEntry) and e.value.message.startswith("target is")
        ]
    assert len(said) == 1
    assert float(said[0].split("roof ")[1].split(" m")[0]) == pytest.approx(12.9, abs=0.5)


def test_a_stepped_tower_flat_in_two_tour_photos_is_not_measured_at_its_lowest_tier() -> None:
    """Town scene 11624: the target, a stepped rectangle (tiers at 8.2, 13.7 and 18.7 m), is
    photographed by the tour from straight above it and from 19 m aside. Neither photo shows
    its upper tiers' walls, and the two agreed on one flat roof at 8.3 m, its lowest tier;
    the overview shows those walls. Taken as measured, the roof let the mission descend to
    measure it again, into the top tier (a crash at 15.4 m). The overview's walls now
    keep it unmeasured, and the flight completes."""
    summary = fly(FlyConfig(scene=str(DATA / "town-11624.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b02"


def test_a_stepped_tower_beside_home_is_not_measured_at_its_lowest_tier() -> None:
    """Town scene 11921: home stands 4 m beside a stepped tower (tiers at 25.1, 41.0 and
    50.3 m, nearly concentric). The second overview, 117 m over home, shows the upper tiers'
    walls inside the lowest tier's outline, but each wall's strip ends where the tier above
    meets the lower tier's edge, two pixels from the ground past the outline, and walls near
    the ground were taken for a courtyard's. The overview and the photo from straight above
    it then agreed on one flat roof at 25.4 m, and the mission descended to look at it from
    48.7 m: into the top tier (a crash, reported as one). A wall whose foot, toward the
    nadir, stands on roof is a higher tier's: the tower stays unmeasured, and the flight
    completes."""
    summary = fly(FlyConfig(scene=str(DATA / "town-11921.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b08"


def test_a_grey_building_a_lawn_outline_touches_is_still_an_obstacle() -> None:
    """World scene 48039: a 19.9 m grey building (b07) stands beside a field of another
    colour. The field's simplified outline reached one pixel into the grey roof, and a
    region sharing any pixel with a building the vectorizer found was taken for that
    building; the field then proved ground, and the grey building was in no obstacle at
    all. The right viewpoint was planned on its roof, 12.5 m up: a crash at 17 m. A region
    is now a found building's only when most of it lies inside the found outlines; the grey
    building is an obstacle, and the flight completes clear of it."""
    summary = fly(FlyConfig(scene=str(DATA / "world-48039.yaml"), no_record=True))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "b06"
    assert summary.clearance_m is not None and summary.clearance_m > 2.0
