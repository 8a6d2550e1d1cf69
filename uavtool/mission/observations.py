"""What the mission observes: the only inputs it has. The runner makes them from the link and
the camera and records each one, in the order the mission consumed it, so replay can feed
the same sequence to a fresh mission."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics

U8Array = npt.NDArray[np.uint8]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Telemetry:
    """One snapshot of the vehicle's state, in the local ENU frame around its home.

    ``time_boot_ms`` is vehicle time (the mission's only clock); ``pos_enu_m`` z is the
    altitude above home; ``gimbal_*`` is the camera's attitude relative to the horizon
    (pitch) and the vehicle's nose (yaw); ``mode`` is in the mission's vocabulary
    (``GUIDED``, ``RTL``, ``LAND``; any other mode by its autopilot's own name, e.g. PX4's
    ``POSCTL``), ``landed`` is true on the ground.
    """

    time_boot_ms: int
    pos_enu_m: Vec3
    vel_enu_m_s: Vec3
    heading_deg: float
    mode: str
    armed: bool
    landed: bool
    gimbal_pitch_deg: float
    gimbal_yaw_deg: float
    battery_pct: int

    @property
    def ground_speed_m_s(self) -> float:
        return math.hypot(self.vel_enu_m_s[0], self.vel_enu_m_s[1])

    @property
    def speed_m_s(self) -> float:
        vx, vy, vz = self.vel_enu_m_s
        return math.sqrt(vx * vx + vy * vy + vz * vz)


@dataclass(frozen=True, slots=True)
class CommandResult:
    """The vehicle's answer to a command the mission issued (``action_id``): accepted, or
    refused / unanswered with the reason. ``final``: the vehicle refused it as one that
    asking again cannot change (MAVLink's ``MAV_RESULT_DENIED``: invalid as given, or
    ``MAV_RESULT_UNSUPPORTED``); a temporary refusal, a failure (ArduPilot's answer while
    its pre-arm checks or position estimate are not ready) or a lost ACK is not."""

    action_id: int
    accepted: bool
    detail: str = ""
    final: bool = False


@dataclass(frozen=True, slots=True)
class Photo:
    """A camera frame taken for ``action_id``, with the camera's pose and intrinsics at
    capture. ``frame_index`` numbers the frames of a flight from 0.

    ``image_rgb`` : (H, W, 3) uint8.
    """

    action_id: int
    frame_index: int
    tag: str
    time_boot_ms: int
    pose: CameraPose
    intrinsics: Intrinsics
    image_rgb: U8Array


@dataclass(frozen=True, slots=True)
class LinkLost:
    """The vehicle has been silent for ``silent_s`` seconds (repeated while it stays so)."""

    silent_s: float


@dataclass(frozen=True, slots=True)
class LinkRestored:
    """The vehicle is heard again after ``silent_s`` seconds of silence."""

    silent_s: float


Observation = Telemetry | CommandResult | Photo | LinkLost | LinkRestored
