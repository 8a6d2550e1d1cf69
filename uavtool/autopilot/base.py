"""The interface every autopilot adapter implements, and what they share."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from uavtool.geo import GeoPoint
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Command, SetGimbal
from uavtool.terminal import safe_text

ParamReader = Callable[[str], float | None]
"""Reads one of the vehicle's parameters by name; None when it does not answer."""

RESULT_NAMES = {
    v: k for k, v in vars(M).items() if k.startswith("MAV_RESULT_") and isinstance(v, int)
}
COMMAND_NAMES = {
    v: k.removeprefix("MAV_CMD_")
    for k, v in vars(M).items()
    if k.startswith("MAV_CMD_") and isinstance(v, int)
}


@dataclass(frozen=True, slots=True)
class Sent:
    """A command on the wire: the MAVLink command number its ACK will carry (0: none)."""

    mav_cmd: int


@dataclass(frozen=True, slots=True)
class Fence:
    """Where the vehicle's geofence, when it would act, keeps it: each limit in metres from
    home (None: no such limit), with the parameter that sets it."""

    alt_max_m: float | None = None
    alt_param: str = ""
    radius_m: float | None = None
    radius_param: str = ""


class Autopilot:
    """One autopilot's conventions. Stateful, one per link: :meth:`mission_mode` may depend
    on what was sent before (PX4 has no GUIDED mode; its adapter emulates one)."""

    name = "MAVLink"

    def mode_name(self, custom_mode: int) -> str:
        """The autopilot's own name of a HEARTBEAT custom mode (what its users see)."""
        raise NotImplementedError

    def mission_mode(self, heartbeat: Any) -> str:
        """The mode in the mission's vocabulary (GUIDED, RTL, LAND, or the autopilot's own
        name for any mode the mission does not ask for)."""
        return self.mode_name(int(heartbeat.custom_mode))

    def prepare(
        self,
        link: VehicleLink,  # noqa: ARG002 - nothing to learn here
        on_wait: Callable[[], None] | None = None,  # noqa: ARG002
    ) -> str:
        """Whatever the adapter must learn from the vehicle before the flight (PX4: its
        events metadata); says what it learnt, for the user ("" for nothing)."""
        return ""

    def vehicle_text(self, msg: Any) -> tuple[int, str] | None:
        """(MAV_SEVERITY, text) when ``msg`` is the vehicle saying something (STATUSTEXT,
        and PX4's events); None for any other message."""
        if msg.get_type() == "STATUSTEXT":
            return int(msg.severity), safe_text(str(msg.text).strip())
        return None

    def param_value(self, msg: Any) -> float:
        """A PARAM_VALUE's value. ArduPilot casts integers to the float it sends."""
        return float(msg.param_value)

    param_types_matter = False
    """Whether PARAM_SET must carry the parameter's own type (read first); ArduPilot takes
    every value as REAL32."""

    def param_encoded(self, value: float, param_type: int) -> float:  # noqa: ARG002
        """What PARAM_SET carries for ``value`` of a parameter of ``param_type``."""
        return float(value)

    def send(self, link: VehicleLink, cmd: Command, home: GeoPoint) -> Sent:
        """Put a mission command on the wire, the way this autopilot takes it."""
        raise NotImplementedError

    def tick(self, link: VehicleLink, now_s: float, home: GeoPoint) -> None:
        """Called on every turn of the runner's loop (``now_s`` on the link's clock): for what
        the autopilot needs sent continuously (PX4's offboard setpoints). Nothing by default."""

    def return_home(self, link: VehicleLink) -> None:
        """Best effort, when the run stops early: the vehicle's own return-to-launch."""
        raise NotImplementedError

    # --- what the pre-flight checks ask -------------------------------------------------------

    def gimbal_fix(self, read: ParamReader) -> str:  # noqa: ARG002 - no names to read
        """What to set when the vehicle reports no gimbal manager (its parameters, by name)."""
        return "configure a gimbal on the autopilot (MAVLink gimbal protocol v2)"

    def mount_v1(self, read: ParamReader) -> tuple[float, float] | None:  # noqa: ARG002
        """The pitch range of a mount this vehicle drives with gimbal protocol v1 only (no
        gimbal manager), from its parameters; None if it has none. From then on the adapter
        points it with DO_MOUNT_CONTROL."""
        return None

    def pitch_fix(self) -> str:
        """What to set when the gimbal cannot pitch from straight down to the horizon."""
        return "give the gimbal a pitch range of -90..0°"

    def fence(self, read: ParamReader) -> Fence | None:  # noqa: ARG002 - none here
        """The vehicle's geofence as it would act; None if off or unknown."""
        return None


def set_mode_long(link: VehicleLink, custom_mode: int, custom_sub_mode: int = 0) -> None:
    link.command_long(
        M.MAV_CMD_DO_SET_MODE, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, custom_mode, custom_sub_mode
    )


def point_mount(link: VehicleLink, cmd: SetGimbal) -> Sent:
    """Point a mount with gimbal protocol v1 (DO_MOUNT_CONTROL, MAVLink targeting)."""
    link.command_long(
        M.MAV_CMD_DO_MOUNT_CONTROL, cmd.pitch_deg, 0.0, cmd.yaw_deg, 0, 0, 0,
        M.MAV_MOUNT_MODE_MAVLINK_TARGETING,
    )  # fmt: skip
    return Sent(M.MAV_CMD_DO_MOUNT_CONTROL)


# SET_POSITION_TARGET: use the position (and yaw when given), ignore velocity, acceleration
# and yaw rate.
_POSITION_ONLY = (
    M.POSITION_TARGET_TYPEMASK_VX_IGNORE
    | M.POSITION_TARGET_TYPEMASK_VY_IGNORE
    | M.POSITION_TARGET_TYPEMASK_VZ_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AX_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AY_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AZ_IGNORE
    | M.POSITION_TARGET_TYPEMASK_YAW_RATE_IGNORE
)


def position_target(
    link: VehicleLink, frame: int, target: GeoPoint, alt_m: float, heading_deg: float | None
) -> Any:
    """A SET_POSITION_TARGET_GLOBAL_INT to ``target`` at ``alt_m`` (in ``frame``'s sense),
    facing ``heading_deg`` (None: any heading)."""
    mask = _POSITION_ONLY | (M.POSITION_TARGET_TYPEMASK_YAW_IGNORE if heading_deg is None else 0)
    yaw = 0.0 if heading_deg is None else math.radians(heading_deg)
    return M.MAVLink_set_position_target_global_int_message(
        0, link.target_system, link.target_component, frame, mask, target.lat_e7,
        target.lon_e7, alt_m, 0, 0, 0, 0, 0, 0, yaw, 0,
    )  # fmt: skip
