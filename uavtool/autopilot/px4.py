"""PX4: main and sub modes in the custom mode, take-off to an altitude above sea level,
movement by DO_REPOSITION in Hold (as QGroundControl's "go to location"; or, with
``movement="offboard"``, a stream of position setpoints in OFFBOARD, as MAVSDK's offboard
plugin), the gimbal through the gimbal manager (protocol v2), and PX4's own parameter names
in every hint.

PX4 has no GUIDED mode. The adapter emulates one: after the mission asks for GUIDED, the
modes the adapter drives the vehicle through — Hold (AUTO.LOITER, where DO_REPOSITION moves
it), AUTO.TAKEOFF and OFFBOARD — read as GUIDED; any other mode the vehicle shows ends that
(whoever switched: the mission to RTL, a pilot, a failsafe), so a later Hold reads as
AUTO.LOITER.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from typing import Any

from uavtool.autopilot.base import (
    Autopilot,
    Fence,
    ParamReader,
    Sent,
    point_mount,
    position_target,
    set_mode_long,
)
from uavtool.autopilot.px4_events import EventDecoder, fetch_decoder
from uavtool.errors import LinkError
from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.link import VehicleLink
from uavtool.link.client import GCS_COMPID, GCS_SYSID
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Arm, Command, GoTo, SetGimbal, SetMode, Takeoff
from uavtool.terminal import safe_text

MAIN_MODES = {1: "MANUAL", 2: "ALTCTL", 3: "POSCTL", 4: "AUTO", 5: "ACRO", 6: "OFFBOARD",
              7: "STABILIZED", 8: "RATTITUDE"}  # fmt: skip
"""PX4's main modes (px4_custom_mode.h)."""
AUTO_SUB_MODES = {1: "READY", 2: "TAKEOFF", 3: "LOITER", 4: "MISSION", 5: "RTL", 6: "LAND",
                  8: "FOLLOW_TARGET", 9: "PRECLAND", 10: "VTOL_TAKEOFF"}  # fmt: skip
POSCTL_SUB_MODES = {1: "ORBIT", 2: "SLOW"}
_AUTO = 4
HOLD = (_AUTO, 3)
TAKEOFF = (_AUTO, 2)
RTL = (_AUTO, 5)
LAND = (_AUTO, 6)
_OURS = {"GUIDED": HOLD, "RTL": RTL, "LAND": LAND}
"""The mission's modes, as PX4 (main, sub) modes."""
OFFBOARD = (6, 0)
_GUIDED_SHOWN_AS = {"AUTO.LOITER", "AUTO.TAKEOFF", "OFFBOARD"}
SETPOINT_S = 0.25
"""How often offboard setpoints go out (PX4 wants at least 2 Hz, and fails over without)."""
OFFBOARD_AFTER_S = 0.5
"""Setpoints streamed this long before OFFBOARD is asked for (PX4 refuses it without)."""
_NAMED_FOR_MISSION = {"AUTO.RTL": "RTL", "AUTO.LAND": "LAND"}

_OFF, _ASKED, _ON = 0, 1, 2
_INT_CODES = {
    M.MAV_PARAM_TYPE_UINT8: "<B", M.MAV_PARAM_TYPE_INT8: "<b",
    M.MAV_PARAM_TYPE_UINT16: "<H", M.MAV_PARAM_TYPE_INT16: "<h",
    M.MAV_PARAM_TYPE_UINT32: "<I", M.MAV_PARAM_TYPE_INT32: "<i",
}  # fmt: skip
_STANDING_REPORTS = {"health", "arming_check"}


def px4_mode(custom_mode: int) -> tuple[int, int]:
    """(main, sub) from a HEARTBEAT custom mode."""
    return (custom_mode >> 16) & 0xFF, (custom_mode >> 24) & 0xFF


def _sub_modes(main: int) -> dict[int, str]:
    return AUTO_SUB_MODES if main == _AUTO else POSCTL_SUB_MODES if main == 3 else {}


def px4_mode_name(main: int, sub: int) -> str:
    name = MAIN_MODES.get(main, f"MODE{main}")
    subs = _sub_modes(main)
    if sub in subs:
        return f"{name}.{subs[sub]}"
    return name if main != _AUTO or sub == 0 else f"{name}.{sub}"


_BY_NAME = {
    px4_mode_name(main, sub): (main, sub)
    for main in MAIN_MODES
    for sub in [0, *_sub_modes(main)]
    if not (main == _AUTO and sub == 0)
}


def _amsl(link: VehicleLink, home: GeoPoint, up_m: float) -> float:
    """``up_m`` above home as an altitude above sea level, by the vehicle's own reckoning:
    the offset between GLOBAL_POSITION_INT's ``alt`` and ``relative_alt``, the height the
    mission flies by. (HOME_POSITION's altitude can differ from it by most of a metre as the
    estimator settles: a target that far off is never "reached".)"""
    pos = link.state.position
    if pos is None:
        return home.alt_amsl_m + up_m
    return (int(pos.alt) - int(pos.relative_alt)) / 1000.0 + up_m


class PX4(Autopilot):
    name = "PX4"
    param_types_matter = True

    def __init__(self, events: EventDecoder | None = None, *, movement: str = "reposition") -> None:
        if movement not in ("reposition", "offboard"):
            raise ValueError(f"PX4 movement is 'reposition' or 'offboard', not {movement!r}")
        self.movement = movement
        self._guided = _OFF
        self._gimbal_control = False
        self._gimbal_v1 = False  # a mount driven by DO_MOUNT_CONTROL (MNT_MODE_IN=3)
        self.events = events
        """Texts for PX4's EVENT messages (None: they read as their numbers)."""
        self._last_said = ("", "")  # (message type, text) of the last thing the vehicle said
        self._setpoint: GoTo | None = None  # offboard: the target streamed, and since when
        self._streaming_since = 0.0
        self._setpoint_sent = -math.inf
        self._offboard_asked = -math.inf

    def prepare(self, link: VehicleLink, on_wait: Callable[[], None] | None = None) -> str:
        if self.events is None:
            try:
                self.events = fetch_decoder(link, on_wait=on_wait)
            except LinkError as exc:
                return f"PX4's events will show as numbers: {exc}"
        return f"PX4's events metadata: {len(self.events)} events"

    def vehicle_text(self, msg: Any) -> tuple[int, str] | None:
        said = self._vehicle_text(msg)
        if said is None:
            return None
        # PX4 says much twice in a row, as a STATUSTEXT and as an event: once is enough (a
        # repeat of the same kind is news again, e.g. the reason for a second refusal).
        text, kind = safe_text(said[1].strip()), msg.get_type()
        last, self._last_said = self._last_said, (kind, text)
        if last[1] == text and last[0] != kind:
            self._last_said = ("", "")
            return None
        return said[0], text

    def _vehicle_text(self, msg: Any) -> tuple[int, str] | None:
        if msg.get_type() != "EVENT":
            return super().vehicle_text(msg)
        if int(msg.log_levels) & 0x0F > M.MAV_SEVERITY_DEBUG:
            return None  # libevents' protocol-level events (summaries for the GCS)
        if self.events is None:
            return int(msg.log_levels) & 0x0F, f"event {int(msg.id)}"
        severity, text = self.events.describe(msg)
        if self.events.group(msg) in _STANDING_REPORTS:
            # What some mode lacks ("No offboard signal", "No manual control input"): kept in
            # the recording, not said as a warning (QGroundControl lists them apart too).
            severity = max(severity, M.MAV_SEVERITY_INFO)
        return severity, text

    def mode_name(self, custom_mode: int) -> str:
        return px4_mode_name(*px4_mode(custom_mode))

    def mission_mode(self, heartbeat: Any) -> str:
        name = self.mode_name(int(heartbeat.custom_mode))
        if self._guided and name in _GUIDED_SHOWN_AS:
            self._guided = _ON
            return "GUIDED"
        if self._guided == _ON:
            self._guided = _OFF  # left for a mode the adapter did not drive it to
        return _NAMED_FOR_MISSION.get(name, name)

    def send(self, link: VehicleLink, cmd: Command, home: GeoPoint) -> Sent:
        if not isinstance(cmd, GoTo | SetGimbal):
            self._setpoint = None  # a mode change or a take-off: the stream stops
        if isinstance(cmd, SetMode):
            mode = _OURS.get(cmd.mode) or _BY_NAME.get(cmd.mode)
            if mode is None:
                raise ValueError(f"unknown PX4 mode {cmd.mode!r}")
            if cmd.mode == "GUIDED":
                self._guided = max(self._guided, _ASKED)
            # Leaving GUIDED: its modes read as GUIDED until the vehicle shows another.
            set_mode_long(link, *mode)
            return Sent(M.MAV_CMD_DO_SET_MODE)
        if isinstance(cmd, Arm):
            link.command_long(M.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
            return Sent(M.MAV_CMD_COMPONENT_ARM_DISARM)
        if isinstance(cmd, Takeoff):  # PX4 takes the altitude above sea level
            nan = math.nan
            amsl = _amsl(link, home, cmd.alt_m)
            link.command_long(M.MAV_CMD_NAV_TAKEOFF, nan, 0, 0, nan, nan, nan, amsl)
            return Sent(M.MAV_CMD_NAV_TAKEOFF)
        if isinstance(cmd, SetGimbal) and self._gimbal_v1:
            return point_mount(link, cmd)
        if isinstance(cmd, SetGimbal):
            if not self._gimbal_control:  # PX4 denies PITCHYAW from a GCS without control
                link.command_long(
                    M.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE, GCS_SYSID, GCS_COMPID, -1, -1
                )
                self._gimbal_control = True
            link.command_long(
                M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
                cmd.pitch_deg,
                cmd.yaw_deg,
                math.nan,
                math.nan,
                0,  # flags: yaw relative to the vehicle ("follow")
            )
            return Sent(M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW)
        if isinstance(cmd, GoTo) and self.movement == "offboard":
            if self._setpoint is None:
                self._streaming_since = link.clock()
            self._setpoint = cmd
            self._send_setpoint(link, cmd, home)
            return Sent(0)  # setpoints have no ACK; OFFBOARD is asked for by tick()
        if isinstance(cmd, GoTo):
            x, y, z = cmd.pos_enu_m
            target = geo_from_enu(home, x, y, 0.0)
            # PX4 takes DO_REPOSITION as COMMAND_INT only in MAV_FRAME_GLOBAL_INT (above sea
            # level), and its yaw in radians.
            yaw = math.nan if cmd.heading_deg is None else math.radians(cmd.heading_deg)
            link.send(
                M.MAVLink_command_int_message(
                    link.target_system,
                    link.target_component,
                    M.MAV_FRAME_GLOBAL_INT,
                    M.MAV_CMD_DO_REPOSITION,
                    0,
                    0,
                    -1.0,  # the vehicle's default speed
                    M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE,
                    0.0,
                    yaw,
                    target.lat_e7,
                    target.lon_e7,
                    _amsl(link, home, z),
                )
            )
            return Sent(M.MAV_CMD_DO_REPOSITION)
        raise TypeError(f"not a vehicle command: {cmd!r}")

    def tick(self, link: VehicleLink, now_s: float, home: GeoPoint) -> None:
        """Offboard: the setpoint again every :data:`SETPOINT_S`, and OFFBOARD asked for (again
        each second until the vehicle shows it) once the stream has run long enough."""
        if self._setpoint is None:
            return
        if now_s - self._setpoint_sent >= SETPOINT_S:
            self._send_setpoint(link, self._setpoint, home)
        shown = link.state.heartbeat
        in_offboard = shown is not None and px4_mode(int(shown.custom_mode)) == OFFBOARD
        if (
            not in_offboard
            and now_s - self._streaming_since >= OFFBOARD_AFTER_S
            and now_s - self._offboard_asked >= 1.0
        ):
            set_mode_long(link, *OFFBOARD)
            self._offboard_asked = now_s

    def _send_setpoint(self, link: VehicleLink, cmd: GoTo, home: GeoPoint) -> None:
        x, y, z = cmd.pos_enu_m
        target = geo_from_enu(home, x, y, 0.0)
        frame, alt = M.MAV_FRAME_GLOBAL_INT, _amsl(link, home, z)
        link.send(position_target(link, frame, target, alt, cmd.heading_deg))
        self._setpoint_sent = link.clock()

    def return_home(self, link: VehicleLink) -> None:
        self._setpoint = None
        set_mode_long(link, *RTL)

    def gimbal_fix(self, read: ParamReader) -> str:
        mode_in = read("MNT_MODE_IN")
        if mode_in is not None and mode_in >= 0:
            return (
                f"MNT_MODE_IN is {mode_in:g} but no gimbal manager answered: set MNT_MODE_IN=4 "
                "(MAVLink gimbal protocol v2) and MNT_MODE_OUT (0: AUX outputs, 2: a MAVLink "
                "gimbal), then reboot PX4"
            )
        return (
            "set MNT_MODE_IN=4 (MAVLink gimbal protocol v2) and MNT_MODE_OUT=0 (AUX outputs; "
            "2 for a MAVLink gimbal), then reboot PX4"
        )

    def mount_v1(self, read: ParamReader) -> tuple[float, float] | None:
        if read("MNT_MODE_IN") != 3:  # MAVLINK_DO_MOUNT: gimbal protocol v1 in
            return None
        low, high = read("MNT_MIN_PITCH"), read("MNT_MAX_PITCH")
        if low is None or high is None:
            return None
        self._gimbal_v1 = True
        return low, high

    def pitch_fix(self) -> str:
        return "set MNT_MIN_PITCH=-90 and MNT_MAX_PITCH=0"

    # PX4 encodes integer parameters bytewise: the int32's four bytes in the float's place
    # (MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE), where ArduPilot casts.

    def param_value(self, msg: Any) -> float:
        code = _INT_CODES.get(int(msg.param_type))
        if code is None:
            return float(msg.param_value)
        raw = struct.pack("<f", float(msg.param_value))
        return float(struct.unpack_from(code, raw)[0])

    def param_encoded(self, value: float, param_type: int) -> float:
        code = _INT_CODES.get(param_type)
        if code is None:
            return float(value)
        raw = struct.pack(code, int(value)).ljust(4, b"\0")
        return float(struct.unpack("<f", raw)[0])

    def fence(self, read: ParamReader) -> Fence | None:
        action = read("GF_ACTION")
        if action is None or action in (0, 1):  # none, or a warning only
            return None
        vertical, horizontal = read("GF_MAX_VER_DIST"), read("GF_MAX_HOR_DIST")
        return Fence(
            alt_max_m=vertical if vertical is not None and vertical > 0 else None,
            alt_param="GF_MAX_VER_DIST",
            radius_m=horizontal if horizontal is not None and horizontal > 0 else None,
            radius_param="GF_MAX_HOR_DIST",
        )
