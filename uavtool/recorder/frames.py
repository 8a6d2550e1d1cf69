"""Camera frames for a flight the recorder does not command, each with the pose it was taken at.

The pose rule: a frame carries the camera pose of the telemetry sample (GLOBAL_POSITION_INT
with the gimbal attitude last reported) nearest its capture in vehicle time.

* The simulated camera renders at the newest sample's pose: capture time *is* that sample's
  ``time_boot_ms``, and the frame shows exactly the recorded pose (``pose_dt_ms`` 0). Against
  where the vehicle really was when the frame was taken, the error is the sample's age:
  at most one telemetry period plus the link's latency (≤ 0.1 s at 10 Hz, i.e. ≤ 1 m at
  10 m/s).
* A real camera's capture time is estimated in vehicle time from the newest sample and the
  wall time elapsed between its arrival and the frame's (a live camera's frames arrive on a
  thread of their own: `uavtool.runner.camera.LatestFrame`); the frame waits (at most
  ``POSE_WAIT_S``) for the next sample so the nearer of the two around it is chosen.
  ``pose_dt_ms`` records the gap; it is at most half a telemetry period (50 ms at 10 Hz)
  plus the link's latency jitter, so the position error is ≤ speed × |pose_dt|.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from dataclasses import dataclass

from uavtool.camera import CameraPose, Intrinsics
from uavtool.images import png_encode
from uavtool.mission import Telemetry
from uavtool.recorder.watch import Event
from uavtool.recording import LogLevel
from uavtool.runner.camera import CameraError, CameraSource
from uavtool.runner.vehicle import camera_pose

POSE_WAIT_S = 0.5
"""How long a real camera's frame waits for the telemetry sample after its capture."""
_KEEP = 64  # telemetry samples kept to choose from (6 s at 10 Hz)


@dataclass(frozen=True, slots=True)
class Frame:
    """One camera frame, ready to record. ``time_boot_ms``: its capture in vehicle time;
    ``pose``: ENU around the recording's origin, from the sample at ``pose_time_boot_ms``."""

    index: int
    png: bytes
    intrinsics: Intrinsics
    time_boot_ms: int
    pose: CameraPose
    pose_time_boot_ms: int
    photo: int
    """The photo's number (from 0), or −1 for a plain video frame."""
    trigger: str

    @property
    def pose_dt_ms(self) -> int:
        return self.pose_time_boot_ms - self.time_boot_ms

    @property
    def tag(self) -> str:
        return f"photo-{self.photo}" if self.photo >= 0 else "frame"


class PoseTrack:
    """Recent telemetry samples with the link-clock time each arrived."""

    def __init__(self) -> None:
        self.samples: deque[tuple[Telemetry, float]] = deque(maxlen=_KEEP)

    def add(self, t: Telemetry, rx_s: float) -> None:
        if self.samples and t.time_boot_ms < self.samples[-1][0].time_boot_ms:
            self.samples.clear()  # the vehicle rebooted: its clock started again
        self.samples.append((t, rx_s))

    @property
    def latest(self) -> Telemetry | None:
        return self.samples[-1][0] if self.samples else None

    def vehicle_ms(self, rx_s: float) -> int:
        """Vehicle time at link-clock time ``rx_s``, from the newest sample."""
        t, at = self.samples[-1]
        return t.time_boot_ms + round((rx_s - at) * 1000.0)

    def nearest(self, time_boot_ms: int) -> Telemetry:
        return min(self.samples, key=lambda s: abs(s[0].time_boot_ms - time_boot_ms))[0]


STALL_PERIODS = 3.0
STALL_MIN_S = 2.0
"""A live camera with nothing new for this many frame periods (and at least this long) at
the end of a recording has stalled."""


class FrameTaker:
    """Takes frames from ``camera`` every ``1/rate_hz`` s (0: never), a photo every
    ``photo_every_s`` (0: never) and on every trigger. ``renders``: the camera renders at the
    pose it is given (simulated), placed ``scene_offset_en_m`` from the recording's origin."""

    def __init__(
        self,
        camera: CameraSource,
        *,
        renders: bool,
        rate_hz: float,
        photo_every_s: float,
        scene_offset_en_m: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        self.camera: CameraSource | None = camera
        self.renders = renders
        self.period_s = 1.0 / rate_hz if rate_hz > 0 else None
        self.photo_every_s = photo_every_s if photo_every_s > 0 else None
        self.offset = scene_offset_en_m
        self.frames = 0
        self.photos = 0
        self.events: list[Event] = []
        self.due = 0
        """Frames the rate asked for so far."""
        self.failed_at_s: float | None = None
        self.last_new_s: float | None = None
        """When the camera last gave a new frame (``time.monotonic``)."""
        self._next_frame_s: float | None = None
        self._next_photo_s: float | None = None
        self._last_taken_s: float | None = None
        # (index, png, intrinsics, capture vehicle ms, photo, trigger, taken at link time)
        self._pending: deque[tuple[int, bytes, Intrinsics, int, int, str, float]] = deque()

    def tick(self, now_s: float, track: PoseTrack, triggers: list[str]) -> list[Frame]:
        """Take what is due now; return the frames whose pose is now known."""
        if self.camera is None or track.latest is None:
            return self._resolve(now_s, track)
        if self._next_frame_s is None:
            self._next_frame_s = now_s
            self._next_photo_s = now_s + (self.photo_every_s or 0.0)
        trigger = triggers[0] if triggers else ""
        if not trigger and self.photo_every_s and now_s >= (self._next_photo_s or 0.0):
            trigger = f"every {self.photo_every_s:g} s"
        if trigger and self.photo_every_s:
            self._next_photo_s = now_s + self.photo_every_s
        due = self.period_s is not None and now_s >= self._next_frame_s
        if due and self.period_s is not None:
            self._next_frame_s = max(self._next_frame_s + self.period_s, now_s)
            self.due += 1
        if trigger or due:
            self._capture(now_s, track, trigger)
        return self._resolve(now_s, track)

    def finish(self, track: PoseTrack) -> list[Frame]:
        """The frames still waiting for a pose, with the best one known."""
        return self._resolve(float("inf"), track)

    def gap(self, *, start_s: float, end_s: float) -> str | None:
        """What the camera failed to give between ``start_s`` and ``end_s`` (monotonic
        seconds): one line, or None when it kept up. A camera stalled for the last
        :data:`STALL_PERIODS` frame periods (and at least :data:`STALL_MIN_S`), or that gave
        under half the frames its rate asked for, did not."""
        if self.failed_at_s is not None:
            return f"camera: failed {self.failed_at_s - start_s:.1f} s in; no frames after"
        if self.period_s is None or self.due < 3:
            return None
        since = self.last_new_s if self.last_new_s is not None else start_s
        stalled_s = end_s - since
        if stalled_s >= max(STALL_PERIODS * self.period_s, STALL_MIN_S):
            return (
                f"camera: nothing new for the last {stalled_s:.1f} s ({self.frames} of "
                f"{self.due} frames due)"
            )
        if self.frames < self.due / 2:
            return f"camera: {self.frames} of {self.due} frames due"
        return None

    def _capture(self, now_s: float, track: PoseTrack, trigger: str) -> None:
        assert self.camera is not None
        t = track.latest
        assert t is not None
        pose = camera_pose(t)
        x, y, z = pose.pos_enu_m
        east, north = self.offset
        at = dataclasses.replace(pose, pos_enu_m=(x + east, y + north, z))
        try:
            image = self.camera.capture(at)
        except CameraError as exc:
            self.events.append(Event(LogLevel.ERROR, f"{exc}; no more frames", "camera"))
            self.camera = None
            self.failed_at_s = now_s
            return
        # A live camera's frame arrived on its own thread, maybe before this tick.
        taken_s = self.camera.captured_at_s
        if taken_s is not None and taken_s == self._last_taken_s and not trigger:
            return  # the same frame as last time: the camera is slower than the frame rate
        self._last_taken_s = taken_s
        self.last_new_s = now_s
        taken_s = now_s if taken_s is None else taken_s
        photo = -1
        if trigger:
            photo = self.photos
            self.photos += 1
            self.events.append(Event(LogLevel.INFO, f"photo {photo} ({trigger})", "camera"))
        taken_ms = t.time_boot_ms if self.renders else track.vehicle_ms(taken_s)
        png = png_encode(image)
        self._pending.append(
            (self.frames, png, self.camera.intrinsics, taken_ms, photo, trigger, taken_s)
        )
        self.frames += 1

    def _resolve(self, now_s: float, track: PoseTrack) -> list[Frame]:
        out = []
        latest = track.latest
        while self._pending and latest is not None:
            index, png, intrinsics, taken_ms, photo, trigger, taken_s = self._pending[0]
            after = latest.time_boot_ms >= taken_ms
            if not (self.renders or after or now_s - taken_s >= POSE_WAIT_S):
                break
            self._pending.popleft()
            sample = track.nearest(taken_ms)
            out.append(
                Frame(
                    index,
                    png,
                    intrinsics,
                    taken_ms,
                    camera_pose(sample),
                    sample.time_boot_ms,
                    photo,
                    trigger,
                )
            )
        return out
