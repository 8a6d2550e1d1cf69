"""What ``uavtool record`` is told, and what it reports when it stops."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from pathlib import Path


class Stop(Enum):
    """Why a recording ended."""

    INTERRUPTED = "interrupted"
    """Ctrl-C (SIGINT) or SIGTERM."""
    DURATION = "duration"
    LANDED = "landed"
    """The vehicle flew, then landed and disarmed (``until_landed``); of a fleet, every
    vehicle that flew has (or fell silent), and no other is armed."""
    VEHICLE_LOST = "vehicle lost"
    """Waiting for a landing (``until_landed``), nothing was heard for ``LOST_S`` (of a
    fleet: from every vehicle, or from every one that flew while the others stayed idle)."""


@dataclass(frozen=True, slots=True)
class RecordConfig:
    """``uavtool record`` options. Durations and rates are on the wall clock.

    ``direct``: the recorder may send its own heartbeat and stream requests, but only while
    no other ground station is heard on the link; without it nothing at all is sent.
    ``camera``: ``none``, ``sim`` (renders ``scene`` at the reported pose), ``opencv:N`` or a
    stream URL. ``rate_hz``: camera frames per second (0: photos only). Photos are taken on
    ``IMAGE_START_CAPTURE`` / ``DO_DIGICAM_CONTROL`` / ``CAMERA_FEEDBACK`` seen on the link,
    and every ``photo_every_s`` (0: never)."""

    connect: str
    output: Path
    direct: bool = False
    camera: str = "none"
    scene: str = "paper"
    rate_hz: float = 1.0
    photo_every_s: float = 0.0
    hfov_deg: float = 60.0
    size_px: tuple[int, int] = (640, 480)
    gimbal_pitch_deg: float = -90.0
    """The camera's pitch when the vehicle reports no gimbal attitude."""
    duration_s: float | None = None
    until_landed: bool = False
    timeout_s: float = 30.0
    """How long to wait for a vehicle's heartbeat and position before giving up."""
    home_wait_s: float = 3.0
    """After the first position, how long to wait for HOME_POSITION before taking the first
    fix as the origin of the local frame."""
    vehicles: int = 1
    """How many vehicles the link carries: the recording starts when this many are heard,
    each with its position; with more than one, vehicle K's topics go under ``/uavK``."""


@dataclass(frozen=True, slots=True)
class VehicleSummary:
    """What was recorded of one vehicle of a fleet."""

    sysid: int
    telemetry: int
    frames: int
    photos: int
    events: int
    gaps: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class RecordSummary:
    path: Path
    stop: Stop
    vehicle: str
    """``sysid N on LINK`` (``sysids 1, 2, 3 on LINK`` for a fleet)."""
    duration_s: float
    messages_in: int
    messages_out: int
    telemetry: int
    frames: int
    photos: int
    events: int
    max_pose_dt_ms: int
    """The largest gap, in vehicle time, between a frame's capture and its pose's sample."""
    gaps: tuple[str, ...] = ()
    """What the file lacks of what was asked for, one line each: a link silent for the end
    of the recording, a camera that stalled or failed. Empty: whole as asked."""
    vehicles: tuple[VehicleSummary, ...] = ()
    """Each vehicle's counts, in system-id order (one for a one-vehicle recording)."""
