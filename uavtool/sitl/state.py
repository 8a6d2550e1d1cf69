"""Small value types shared by the SITL's autopilot, protocol handlers and telemetry."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from uavtool.mavlink.dialect import mavlink

# Global frames by altitude reference; the float and _INT variants mean the same here.
RELATIVE_ALT_FRAMES = frozenset(
    {mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT, mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT}
)
AMSL_FRAMES = frozenset({mavlink.MAV_FRAME_GLOBAL, mavlink.MAV_FRAME_GLOBAL_INT})


class Mode(IntEnum):
    """The ArduCopter flight modes the built-in vehicle flies (HEARTBEAT custom_mode)."""

    STABILIZE = 0
    ALT_HOLD = 2
    AUTO = 3
    GUIDED = 4
    LOITER = 5
    RTL = 6
    LAND = 9
    POSHOLD = 16
    BRAKE = 17


ARMABLE_MODES = frozenset(
    {Mode.STABILIZE, Mode.ALT_HOLD, Mode.GUIDED, Mode.LOITER, Mode.POSHOLD, Mode.BRAKE}
)


@dataclass(frozen=True, slots=True)
class Result:
    """The outcome of a command: a MAV_RESULT and, when refused, the reason (sent as STATUSTEXT)."""

    code: int
    reason: str | None = None

    @property
    def ok(self) -> bool:
        return bool(self.code == mavlink.MAV_RESULT_ACCEPTED)


ACCEPTED = Result(mavlink.MAV_RESULT_ACCEPTED)
UNSUPPORTED = Result(mavlink.MAV_RESULT_UNSUPPORTED)


def denied(reason: str) -> Result:
    return Result(mavlink.MAV_RESULT_DENIED, reason)


def failed(reason: str) -> Result:
    return Result(mavlink.MAV_RESULT_FAILED, reason)


@dataclass(frozen=True, slots=True)
class MissionItem:
    """One MISSION_ITEM_INT as stored on the vehicle (x/y are degE7 for global frames)."""

    seq: int
    frame: int
    command: int
    current: int
    autocontinue: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: int
    y: int
    z: float
    mission_type: int = 0


@dataclass(slots=True)
class Gimbal:
    """Gimbal angles in degrees: pitch −90 (down) … 0 (forward); yaw relative to the vehicle
    unless ``yaw_locked`` (then earth-frame heading)."""

    pitch_deg: float = 0.0
    yaw_deg: float = 0.0
    target_pitch_deg: float = 0.0
    target_yaw_deg: float = 0.0
    yaw_locked: bool = False
    rate_dps: float = 90.0
