"""The camera mount as ArduCopter has one: configured by ``MNT1_TYPE`` at boot only.

ArduPilot creates its mount backend when it boots. With ``MNT1_TYPE`` 0 (its default)
there is no mount: DO_MOUNT_CONTROL and the gimbal manager commands are answered
MAV_RESULT_FAILED with no STATUSTEXT, and no gimbal message is sent. A type set later takes
effect only after a reboot; until then arming fails with "Arm: Mount: check TYPE".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from uavtool.camera import CameraPose, Quaternion, camera_from_attitude
from uavtool.sitl.params import ParamStore
from uavtool.sitl.physics import State
from uavtool.sitl.state import Gimbal

NADIR: Quaternion = (math.sqrt(0.5), 0.0, -math.sqrt(0.5), 0.0)
"""A camera fixed to the frame looking straight down (pitch −90° in the body frame)."""

SERVO_ROLL_TRIM_DEG = 0.13
"""The roll a stabilised servo mount keeps at rest (ArduCopter's SITL servo mount reported
0.13° at −90° pitch): its quaternion is never a pure pitch."""


@dataclass(frozen=True, slots=True)
class Mount:
    """The mount the vehicle booted with. ``roll_trim_deg``: the stabilisation residual it
    reports and the camera really has."""

    present: bool
    roll_trim_deg: float = 0.0

    @classmethod
    def at_boot(cls, params: ParamStore, *, roll_trim_deg: float) -> Mount:
        present = int(params["MNT1_TYPE"]) != 0
        return cls(present, roll_trim_deg if present else 0.0)

    def pre_arm_failure(self, params: ParamStore) -> str | None:
        """ArduPilot's mount pre-arm check (without its "Arm: " prefix)."""
        if int(params["MNT1_TYPE"]) != 0 and not self.present:
            return "Mount: check TYPE"
        return None


def gimbal_quaternion(gimbal: Gimbal, mount: Mount) -> Quaternion:
    """The attitude the gimbal reports (GIMBAL_DEVICE_ATTITUDE_STATUS ``q``): roll and pitch
    from the horizon, yaw from the nose, Z-Y-X order."""
    half_r = math.radians(mount.roll_trim_deg) / 2
    half_p = math.radians(gimbal.pitch_deg) / 2
    half_y = math.radians(gimbal.yaw_deg) / 2
    cr, sr = math.cos(half_r), math.sin(half_r)
    cp, sp = math.cos(half_p), math.sin(half_p)
    cy, sy = math.cos(half_y), math.sin(half_y)
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def true_camera_pose(state: State, gimbal: Gimbal, mount: Mount) -> CameraPose:
    """Where the camera really looks, ENU around home: through the gimbal when there is a
    mount, else straight down through the frame (tilting with it)."""
    north, east, down = state.pos_ned_m
    pos = (east, north, -down)
    if not mount.present:
        return camera_from_attitude(
            pos,
            vehicle_heading_deg=state.yaw_deg,
            gimbal_q=NADIR,
            yaw_in_vehicle_frame=True,
            vehicle_roll_deg=state.roll_deg,
            vehicle_pitch_deg=state.pitch_deg,
            stabilised=False,
        )
    return camera_from_attitude(
        pos,
        vehicle_heading_deg=state.yaw_deg,
        gimbal_q=gimbal_quaternion(gimbal, mount),
        yaw_in_vehicle_frame=True,
    )
