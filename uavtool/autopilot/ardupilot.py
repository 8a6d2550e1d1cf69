"""ArduPilot (ArduCopter), and the built-in vehicle that follows it: custom modes by number,
GUIDED position targets, NAV_TAKEOFF above home, DO_MOUNT_CONTROL for the mount."""

from __future__ import annotations

import math

from uavtool.autopilot.base import (
    Autopilot,
    Fence,
    ParamReader,
    Sent,
    point_mount,
    position_target,
    set_mode_long,
)
from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import COPTER_MODE_NAMES, COPTER_MODES
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Arm, Command, GoTo, SetGimbal, SetMode, Takeoff

_FENCE_ALT_MAX, _FENCE_CIRCLE = 1, 2
"""FENCE_TYPE bits (ArduPilot's AC_FENCE_TYPE_ALT_MAX and AC_FENCE_TYPE_CIRCLE)."""
SERVO_MOUNT_FIX = (
    "set MNT1_TYPE=1 (servo) with SERVO9_FUNCTION=7 (mount pitch) and SERVO10_FUNCTION=6 "
    "(mount yaw), e.g. in a defaults file, and reboot the autopilot (ArduPilot reads "
    "MNT1_TYPE only at boot)"
)


class ArduPilot(Autopilot):
    name = "ArduPilot"

    def mode_name(self, custom_mode: int) -> str:
        return COPTER_MODE_NAMES.get(custom_mode, f"MODE{custom_mode}")

    def send(self, link: VehicleLink, cmd: Command, home: GeoPoint) -> Sent:
        if isinstance(cmd, SetMode):
            number = COPTER_MODES.get(cmd.mode)
            if number is None:
                raise ValueError(f"unknown ArduCopter mode {cmd.mode!r}")
            set_mode_long(link, number)
            return Sent(M.MAV_CMD_DO_SET_MODE)
        if isinstance(cmd, Arm):
            link.command_long(M.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
            return Sent(M.MAV_CMD_COMPONENT_ARM_DISARM)
        if isinstance(cmd, Takeoff):  # altitude above home
            link.command_long(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, cmd.alt_m)
            return Sent(M.MAV_CMD_NAV_TAKEOFF)
        if isinstance(cmd, SetGimbal):
            return point_mount(link, cmd)
        if isinstance(cmd, GoTo):
            x, y, z = cmd.pos_enu_m
            target = geo_from_enu(home, x, y, 0.0)
            frame = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
            link.send(position_target(link, frame, target, z, cmd.heading_deg))
            return Sent(0)  # position targets have no ACK
        raise TypeError(f"not a vehicle command: {cmd!r}")

    def return_home(self, link: VehicleLink) -> None:
        set_mode_long(link, COPTER_MODES["RTL"])

    def gimbal_fix(self, read: ParamReader) -> str:
        value = read("MNT1_TYPE")
        if value is not None and value != 0:
            return (
                f"MNT1_TYPE is {value:g} but no mount started: reboot the autopilot "
                "(ArduPilot reads MNT1_TYPE only at boot)"
            )
        return f"MNT1_TYPE=0; {SERVO_MOUNT_FIX}"

    def pitch_fix(self) -> str:
        return "set MNT1_PITCH_MIN=-90 and MNT1_PITCH_MAX=0"

    def fence(self, read: ParamReader) -> Fence | None:
        enabled = read("FENCE_ENABLE")
        if enabled is None:  # no fence parameters: one unanswered question, not four
            return None
        values = [read(n) for n in ("FENCE_TYPE", "FENCE_ALT_MAX", "FENCE_RADIUS")]
        if None in values or not enabled:
            return None
        types, alt_max, radius = (float(v) for v in values if v is not None)
        return Fence(
            alt_max_m=alt_max if int(types) & _FENCE_ALT_MAX else None,
            alt_param="FENCE_ALT_MAX",
            radius_m=radius if int(types) & _FENCE_CIRCLE else None,
            radius_param="FENCE_RADIUS",
        )


class GenericMAVLink(ArduPilot):
    """A vehicle that is neither ArduPilot nor PX4: ArduPilot's commands (the most widely
    followed), but no parameter names in the hints — they would be ArduPilot's."""

    name = "MAVLink"

    def gimbal_fix(self, read: ParamReader) -> str:
        return Autopilot.gimbal_fix(self, read)

    def pitch_fix(self) -> str:
        return Autopilot.pitch_fix(self)

    def fence(self, read: ParamReader) -> Fence | None:  # noqa: ARG002 - names unknown
        return None
