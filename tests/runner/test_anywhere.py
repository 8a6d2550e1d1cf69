"""The mission anywhere on Earth: the paper's buildings with the target across the 180th
meridian (eastward and westward), at 84° north and south, across the equator and Greenwich at
once, and from other headings. The flight is the same flight: the same decision and model,
the same route within centimetres (the geo maths are flat-earth, as ArduPilot's), and every
fix in the recording a real place beside home."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.mission import Status
from uavtool.recording import LocationFix, RecordingReader
from uavtool.recording.topics import FIX
from uavtool.runner.fly import FlyConfig, fly
from uavtool.world import load_scene

# 8 m of longitude at 50° N is 0.000112°; the red target stands 5-15 m east of home, yellow
# and blue 7-17 m west
PLACES = {
    "date-line-east": (50.0647, 179.999888, 0.0),  # red across the line, east of it
    "date-line-west": (50.0647, -179.999888, 0.0),  # yellow and blue across it, west
    "north-84": (84.0, -179.9999, 0.0),
    "south-84": (-84.0, 179.99995, 0.0),
    "equator-greenwich": (0.00005, -0.0001, 135.0),
    "date-line-heading-250": (-33.9, 179.99991, 250.0),
}


@pytest.fixture(scope="module")
def paper_route_m() -> float:
    summary = fly(FlyConfig(no_record=True))
    assert summary.outcome.status is Status.COMPLETED
    return summary.route_length_m


@pytest.mark.parametrize("place", PLACES)
def test_the_mission_flies_the_same_anywhere(
    tmp_path: Path, place: str, paper_route_m: float
) -> None:
    lat, lon, heading = PLACES[place]
    scene = load_scene("paper")
    home = GeoPoint(lat, lon, scene.home.alt_amsl_m)
    moved = dataclasses.replace(scene, home=home, home_heading_deg=heading)
    record = tmp_path / "anywhere.mcap"
    summary = fly(FlyConfig(scene=moved, record=record))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == "red"
    if heading == 0.0:
        assert summary.route_length_m == pytest.approx(paper_route_m, abs=0.5)
    fixes = 0
    with RecordingReader(record) as reader:
        for entry in reader.entries([FIX]):
            fix = entry.value
            assert isinstance(fix, LocationFix)
            assert -90.0 <= fix.latitude_deg <= 90.0 and -180.0 <= fix.longitude_deg <= 180.0
            east, north, _ = enu_from_geo(home, GeoPoint(fix.latitude_deg, fix.longitude_deg, 0.0))
            assert abs(east) < 100.0 and abs(north) < 100.0  # beside home, not across the world
            fixes += 1
    assert fixes > 1000
