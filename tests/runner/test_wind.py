"""The mission in the wind on the built-in vehicle: the wind changes the flight, the photos are
taken where the recording says they were, and a wind beyond what the lean can hold ends the
flight honestly."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from uavtool.camera import CameraPose
from uavtool.mission import Photo, Status
from uavtool.replay import load_flight
from uavtool.runner import camera as runner_camera
from uavtool.runner.fly import FlyConfig, fly

TURBULENT = (("SIM_WIND_TURB", 2.0),)


def test_photos_record_the_pose_they_were_taken_from_in_gusty_wind(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """10 m/s from the west with turbulence: the vehicle leans ~25° and is shaken, yet every
    photo's recorded pose is where the simulated camera really was at the shutter (the
    gimbal holds the camera level; the telemetry lags the vehicle by under 0.1 s)."""
    rendered: list[CameraPose] = []
    capture = runner_camera.SimCamera.capture

    def spy(self: runner_camera.SimCamera, pose: CameraPose) -> object:
        rendered.append(pose)
        return capture(self, pose)

    monkeypatch.setattr(runner_camera.SimCamera, "capture", spy)
    record = tmp_path / "wind.mcap"
    summary = fly(FlyConfig(wind=(10.0, 270.0), vehicle_params=TURBULENT, seed=7, record=record))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building
    photos = [o for o in load_flight(record).observations if isinstance(o, Photo)]
    assert len(photos) == len(rendered) >= 7  # 2 overviews, red, top, 3 sides
    for photo, true in zip(photos, rendered, strict=True):
        recorded = photo.pose
        assert math.dist(recorded.pos_enu_m, true.pos_enu_m) < 0.1, photo.tag
        assert abs((recorded.heading_deg - true.heading_deg + 180) % 360 - 180) < 1.0, photo.tag
        assert recorded.pitch_deg == pytest.approx(true.pitch_deg, abs=0.5), photo.tag
        assert recorded.roll_deg == pytest.approx(true.roll_deg, abs=0.5), photo.tag


def test_wind_makes_the_flight_longer_and_costs_battery() -> None:
    calm = fly(FlyConfig(no_record=True))
    windy = fly(FlyConfig(wind=(10.0, 270.0), vehicle_params=TURBULENT, no_record=True))
    for s in (calm, windy):
        assert s.outcome.status is Status.COMPLETED, s.outcome.reason
    assert windy.flight_time_s > calm.flight_time_s
    assert windy.route_length_m > calm.route_length_m


def test_a_wind_the_vehicle_cannot_hold_ends_the_flight_honestly() -> None:
    """16 m/s: past what a 30° lean holds (~10 m/s of airspeed for this airframe), the vehicle
    drifts downwind; the mission sees it never reaches its overview point and gives up."""
    summary = fly(FlyConfig(wind=(16.0, 270.0), vehicle_params=TURBULENT, no_record=True))
    assert summary.outcome.status is Status.ABORTED
    assert "never reached" in summary.outcome.reason
    assert summary.evaluation.matched_building == ""
