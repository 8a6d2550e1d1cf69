"""The fake vehicle itself: it must behave like the vehicle the tests claim it is."""

from __future__ import annotations

import numpy as np

from tests.mission.fakes import REFUSED, FakeVehicle
from uavtool.camera import CameraPose
from uavtool.mission import Arm, CommandResult, GoTo, Photo, SetGimbal, SetMode, Takeoff, TakePhoto
from uavtool.world import Scene, render


def _ticks(fake: FakeVehicle, n: int) -> None:
    for _ in range(n):
        fake.tick()


def test_takes_off_flies_at_its_speed_and_stops_at_the_target(paper: Scene) -> None:
    fake = FakeVehicle(paper, speed_m_s=5.0, climb_m_s=2.0)
    assert fake.execute(Takeoff(1, 10.0)) == CommandResult(1, False, "refused (MAV_RESULT_FAILED)")
    assert fake.execute(SetMode(2, "GUIDED")) == CommandResult(2, True, "")
    assert fake.execute(Arm(3)) == CommandResult(3, True, "")
    assert fake.execute(Takeoff(4, 10.0)) == CommandResult(4, True, "")
    _ticks(fake, 10)
    t = fake.telemetry()
    assert t.time_boot_ms == 1000 and abs(t.pos_enu_m[2] - 2.0) < 1e-9 and not t.landed
    _ticks(fake, 45)  # 10 m at 2 m/s, then it holds exactly there
    assert fake.telemetry().pos_enu_m == (0.0, 0.0, 10.0)
    assert fake.execute(GoTo(5, (30.0, 40.0, 10.0), 90.0)) == CommandResult(5, True, "sent")
    _ticks(fake, 1)
    assert abs(fake.telemetry().ground_speed_m_s - 5.0) < 1e-9
    _ticks(fake, 103)  # 50 m at 5 m/s: there after 10 s, then still
    t = fake.telemetry()
    assert t.pos_enu_m == (30.0, 40.0, 10.0) and t.speed_m_s == 0.0
    assert t.heading_deg == 90.0


def test_rtl_comes_home_lands_and_disarms(paper: Scene) -> None:
    fake = FakeVehicle(paper, airborne=(20.0, -10.0, 8.0), rtl_alt_m=15.0)
    fake.execute(SetMode(1, "RTL"))
    heights = []
    for _ in range(300):
        fake.tick()
        heights.append(fake.pos[2])
    assert max(heights) == 15.0  # climbs to the RTL altitude first
    assert fake.landed and not fake.armed and fake.pos == (0.0, 0.0, 0.0)


def test_refusals_and_silences_are_counted(paper: Scene) -> None:
    fake = FakeVehicle(paper, refuse={"SetMode:GUIDED": 1}, ignore={"SetGimbal": 1})
    assert fake.execute(SetMode(1, "GUIDED")) == CommandResult(1, False, REFUSED)
    assert fake.execute(SetMode(2, "RTL")) == CommandResult(2, True, "")
    assert fake.execute(SetMode(3, "GUIDED")) == CommandResult(3, True, "")
    assert fake.execute(SetGimbal(4, -90.0)) is None
    assert fake.execute(SetGimbal(5, -90.0)) == CommandResult(5, True, "")


def test_photo_is_the_scene_rendered_at_the_camera_pose(paper: Scene) -> None:
    fake = FakeVehicle(paper, airborne=(1.0, 2.0, 45.0))
    fake.execute(SetGimbal(1, -90.0))
    _ticks(fake, 10)
    photo = fake.execute(TakePhoto(2, "overview"))
    assert isinstance(photo, Photo) and photo.frame_index == 0 and photo.action_id == 2
    pose = CameraPose((1.0, 2.0, 45.0), paper.home_heading_deg, -90.0)
    assert photo.pose == pose
    assert np.array_equal(photo.image_rgb, render(paper, pose, photo.intrinsics))
