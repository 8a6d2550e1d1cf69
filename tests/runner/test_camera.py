"""A live camera is read on a thread of its own (`LatestFrame`): the newest frame, with when
it arrived, is handed out at once; a camera that fails, never starts or stops giving frames is
a `CameraError`. Frames recorded from it (`FrameTaker`) are dated by their arrival."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission import Telemetry
from uavtool.recorder.frames import FrameTaker, PoseTrack
from uavtool.runner import camera as cameras
from uavtool.runner.camera import CameraError, LatestFrame

K = Intrinsics.from_hfov(width_px=8, height_px=6, hfov_deg=60.0)
POSE = CameraPose((0.0, 0.0, 10.0), 0.0, -90.0)


class SlowCamera:
    """Gives frame k (all pixels k) every ``period_s``; fails after ``fail_after`` frames;
    blocks for good after ``stall_after`` frames."""

    def __init__(
        self, period_s: float, *, fail_after: int = 10**9, stall_after: int = 10**9
    ) -> None:
        self.name, self.intrinsics, self.captured_at_s = "slow", K, None
        self.period_s, self.fail_after, self.stall_after = period_s, fail_after, stall_after
        self.count = 0
        self.closed = False
        self.release = threading.Event()

    def capture(self, pose: CameraPose) -> np.ndarray:
        if self.count >= self.stall_after:
            self.release.wait()
        if self.count >= self.fail_after:
            raise CameraError("camera slow: unplugged")
        time.sleep(self.period_s)
        self.count += 1
        return np.full((6, 8, 3), self.count % 256, np.uint8)

    def close(self) -> None:
        self.closed = True


def test_the_newest_frame_is_handed_out_at_once() -> None:
    slow = SlowCamera(0.2)
    live = LatestFrame(slow)
    try:
        first = live.capture(POSE)  # waits for the first frame
        t0 = time.monotonic()
        again = live.capture(POSE)
        assert time.monotonic() - t0 < 0.1  # not another 0.2 s read
        assert live.captured_at_s is not None and live.captured_at_s <= time.monotonic()
        assert int(again[0, 0, 0]) >= int(first[0, 0, 0])
        time.sleep(0.7)
        later = live.capture(POSE)
        assert int(later[0, 0, 0]) >= int(again[0, 0, 0]) + 2  # it kept reading meanwhile
    finally:
        live.close()
    assert slow.closed


def test_a_camera_that_fails_is_a_camera_error() -> None:
    live = LatestFrame(SlowCamera(0.01, fail_after=2))
    error: CameraError | None = None
    deadline = time.monotonic() + 5.0
    while error is None and time.monotonic() < deadline:
        try:
            live.capture(POSE)
        except CameraError as exc:
            error = exc
        time.sleep(0.01)
    live.close()
    assert error is not None and "unplugged" in str(error)


def test_a_camera_that_never_starts_or_stalls_is_a_camera_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(cameras, "FIRST_FRAME_S", 0.2)
    never = SlowCamera(0.0, stall_after=0)
    with pytest.raises(CameraError, match=r"no frame in 0\.2 s"):
        LatestFrame(never).capture(POSE)
    never.release.set()

    now = [100.0]
    stalls = SlowCamera(0.0, stall_after=1)
    live = LatestFrame(stalls, clock=lambda: now[0])
    live.capture(POSE)
    now[0] += cameras.STALE_S + 0.1  # no new frame since
    with pytest.raises(CameraError, match="no new frame for 2 s"):
        live.capture(POSE)
    stalls.release.set()
    live.close()


class _Held:
    """A live camera whose newest frame arrived at ``at`` (link-clock seconds)."""

    def __init__(self, at: float) -> None:
        self.name, self.intrinsics, self.captured_at_s = "held", K, at

    def capture(self, pose: CameraPose) -> np.ndarray:
        return np.zeros((6, 8, 3), np.uint8)

    def close(self) -> None:
        pass


def test_recorded_frames_are_dated_by_their_arrival_and_never_twice() -> None:
    track = PoseTrack()
    sample = Telemetry(
        time_boot_ms=10_000,
        pos_enu_m=(0.0, 0.0, 10.0),
        vel_enu_m_s=(0.0, 0.0, 0.0),
        heading_deg=0.0,
        mode="GUIDED",
        armed=True,
        landed=False,
        gimbal_pitch_deg=-90.0,
        gimbal_yaw_deg=0.0,
        battery_pct=100,
    )
    track.add(sample, rx_s=50.0)
    held = _Held(at=49.8)  # arrived 0.2 s before the sample
    taker = FrameTaker(held, renders=False, rate_hz=10.0, photo_every_s=0.0)
    (frame,) = taker.tick(50.0, track, [])  # a sample after it is known: resolved at once
    assert frame.time_boot_ms == 9_800 and frame.pose_dt_ms == 200
    assert taker.tick(50.1, track, []) == []  # the same frame again: not recorded twice
    assert taker.finish(track) == [] and taker.frames == 1
    (photo,) = [*taker.tick(50.2, track, ["trigger"]), *taker.finish(track)]
    assert photo.photo == 0  # a trigger records the frame there is, even the same one
