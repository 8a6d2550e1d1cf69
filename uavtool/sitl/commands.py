"""COMMAND_LONG / COMMAND_INT handlers: one function per MAV_CMD, chosen from a table.

Each handler returns a :class:`Result`; the caller sends exactly one COMMAND_ACK for it,
plus a STATUSTEXT with the reason when the command is refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from uavtool.geo import GeoPoint
from uavtool.mavlink.dialect import mavlink as M
from uavtool.sitl.args import (
    MSG_ID_MAX,
    UINT8_MAX,
    UINT16_MAX,
    UINT32_MAX,
    lat_lon_ok,
    whole,
)
from uavtool.sitl.autopilot import FORCE_MAGIC
from uavtool.sitl.state import (
    ACCEPTED,
    AMSL_FRAMES,
    RELATIVE_ALT_FRAMES,
    Mode,
    Result,
    denied,
    failed,
)

if TYPE_CHECKING:
    from uavtool.sitl.gcs import GcsSession


@dataclass(frozen=True, slots=True)
class CommandArgs:
    """A command with its parameters, whether it came as COMMAND_LONG or COMMAND_INT.

    For COMMAND_INT, ``x``/``y`` are degE7 (or local) integers and ``frame`` is set; for
    COMMAND_LONG ``frame`` is None and params 5/6 hold degrees.
    """

    command: int
    params: tuple[float, float, float, float, float, float, float]
    frame: int | None
    x: int
    y: int
    source: tuple[int, int]

    def p(self, n: int) -> float:
        return self.params[n - 1]


Handler = Callable[["GcsSession", CommandArgs], Result]


def _arm_disarm(session: GcsSession, cmd: CommandArgs) -> Result:
    force = cmd.p(2) == FORCE_MAGIC
    if cmd.p(1) == 1.0:
        return session.ap.arm(force=force)
    if cmd.p(1) == 0.0:
        return session.ap.disarm(force=force)
    return denied(f"Arm: param1 must be 0 or 1, got {cmd.p(1):g}")


def _takeoff(session: GcsSession, cmd: CommandArgs) -> Result:
    return session.ap.takeoff(cmd.p(7))


def _land(session: GcsSession, cmd: CommandArgs) -> Result:
    if not session.ap.armed:
        return failed("Land: vehicle not armed")
    return session.ap.set_mode(Mode.LAND)


def _rtl(session: GcsSession, cmd: CommandArgs) -> Result:
    return session.ap.set_mode(Mode.RTL)


def _set_mode(session: GcsSession, cmd: CommandArgs) -> Result:
    base_mode, custom_mode = whole(cmd.p(1), 0, UINT8_MAX), whole(cmd.p(2), 0, UINT32_MAX)
    if base_mode is None or custom_mode is None:
        return denied(f"Set mode: bad mode {cmd.p(1):g}, {cmd.p(2):g}")
    if not base_mode & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
        return denied("Set mode: only custom (ArduCopter) modes are supported")
    return session.set_mode_number(custom_mode)


def _condition_yaw(session: GcsSession, cmd: CommandArgs) -> Result:
    # ArduCopter's checks: angle 0…360, param4 0 (absolute) or 1 (relative).
    if not 0.0 <= cmd.p(1) <= 360.0:
        return denied(f"Yaw: angle {cmd.p(1):g} not in 0-360")
    if cmd.p(4) not in (0.0, 1.0):
        return denied(f"Yaw: param4 {cmd.p(4):g} must be 0 (absolute) or 1")
    direction = -1 if cmd.p(3) < 0 else 1  # NaN: clockwise
    return session.ap.condition_yaw(cmd.p(1), cmd.p(2), direction, cmd.p(4) == 1.0)


def _change_speed(session: GcsSession, cmd: CommandArgs) -> Result:
    speed_type = whole(cmd.p(1), 0, 3)
    if speed_type is None:
        return denied(f"Change speed: unknown speed type {cmd.p(1):g}")
    return session.ap.change_speed(speed_type, cmd.p(2))


def _reposition(session: GcsSession, cmd: CommandArgs) -> Result:
    ap = session.ap
    if cmd.frame is None:
        lat, lon, frame = cmd.p(5), cmd.p(6), M.MAV_FRAME_GLOBAL_RELATIVE_ALT
    else:
        lat, lon, frame = cmd.x / 1e7, cmd.y / 1e7, cmd.frame
    if frame in RELATIVE_ALT_FRAMES:
        alt_rel = cmd.p(7)
    elif frame in AMSL_FRAMES:
        alt_rel = cmd.p(7) - ap.home.alt_amsl_m
    else:
        return denied(f"Reposition: unsupported frame {frame}")
    if not (lat_lon_ok(lat, lon) and math.isfinite(alt_rel)):
        return denied("Reposition: no such position")
    flags = whole(cmd.p(2), 0, UINT32_MAX)
    if flags is None:
        return denied(f"Reposition: bad flags {cmd.p(2):g}")
    n, e, _ = ap.ned_of(GeoPoint(lat, lon, ap.home.alt_amsl_m))
    if cmd.p(1) > 0:
        speed = ap.change_speed(1, cmd.p(1))
        if not speed.ok:
            return speed
    # param4 (yaw) is ignored, as ArduCopter does: clients disagree on its unit (MAVSDK
    # sends radians, the spec says degrees); yaw is set with CONDITION_YAW or a target.
    change_mode = bool(flags & M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE)
    return ap.guided_position((n, e, -alt_rel), switch_mode=change_mode)


def _mount_control(session: GcsSession, cmd: CommandArgs) -> Result:
    # param1 pitch, param3 yaw (body frame), degrees; param7 mount mode.
    return session.ap.set_gimbal(pitch_deg=cmd.p(1), yaw_deg=cmd.p(3))


def _gimbal_pitchyaw(session: GcsSession, cmd: CommandArgs) -> Result:
    if cmd.p(7) not in (0.0, 1.0):
        return denied(f"Gimbal: no gimbal device {cmd.p(7):g}")
    flags = whole(cmd.p(5), 0, UINT32_MAX) or 0
    locked = bool(flags & M.GIMBAL_MANAGER_FLAGS_YAW_LOCK)
    return session.ap.set_gimbal(pitch_deg=cmd.p(1), yaw_deg=cmd.p(2), yaw_locked=locked)


def _gimbal_configure(session: GcsSession, cmd: CommandArgs) -> Result:
    # param1/2: the primary controller's sysid/compid: 0-255, -1 leave, -2 the sender, -3 none.
    sysid, compid = whole(cmd.p(1), -3, UINT8_MAX), whole(cmd.p(2), -3, UINT8_MAX)
    if sysid is None or compid is None:
        return denied(f"Gimbal: bad controller {cmd.p(1):g}/{cmd.p(2):g}")
    if sysid == -1:
        return ACCEPTED
    if sysid == -2:
        sysid, compid = cmd.source
    elif sysid == -3:
        sysid, compid = 0, 0
    session.ap.gimbal_owner = (sysid, max(compid, 0))
    return ACCEPTED


GIMBAL_MESSAGES = frozenset(
    {
        M.MAVLINK_MSG_ID_GIMBAL_DEVICE_ATTITUDE_STATUS,
        M.MAVLINK_MSG_ID_GIMBAL_MANAGER_STATUS,
        M.MAVLINK_MSG_ID_GIMBAL_MANAGER_INFORMATION,
        M.MAVLINK_MSG_ID_GIMBAL_DEVICE_INFORMATION,
    }
)


def _request_message(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = whole(cmd.p(1), 0, MSG_ID_MAX)
    if msg_id is None:
        return denied(f"Request message: no message id {cmd.p(1):g}")
    msg = session.telemetry.build(msg_id)
    if msg is None and msg_id in GIMBAL_MESSAGES:
        return ACCEPTED  # as ArduPilot: a known message, nothing to send without a mount
    if msg is None:
        return failed(f"Request message: message {msg_id} is not available")
    session.defer(msg)  # sent right after the ACK
    return ACCEPTED


def _request_autopilot_version(session: GcsSession, cmd: CommandArgs) -> Result:
    session.defer(session.telemetry.autopilot_version())
    return ACCEPTED


def _set_message_interval(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = whole(cmd.p(1), 0, UINT16_MAX)
    if msg_id is None:
        return denied(f"Set message interval: no message id {cmd.p(1):g}")
    if not (math.isfinite(cmd.p(2)) and cmd.p(2) >= -1):
        return denied(f"Set message interval: bad interval {cmd.p(2):g} us")
    if session.telemetry.builders.get(msg_id) is None:
        return failed(f"Set message interval: message {msg_id} is not streamed")
    session.streams.set_interval(msg_id, cmd.p(2), session.ap.now_ns)
    return ACCEPTED


def _get_message_interval(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = whole(cmd.p(1), 0, UINT16_MAX)  # MESSAGE_INTERVAL carries it as a uint16
    if msg_id is None:
        return denied(f"Get message interval: no message id {cmd.p(1):g}")
    interval_ns = session.streams.interval_ns.get(msg_id)
    interval_us = -1 if interval_ns is None else interval_ns // 1000
    session.defer(M.MAVLink_message_interval_message(msg_id, interval_us))
    return ACCEPTED


def _get_home(session: GcsSession, cmd: CommandArgs) -> Result:
    session.defer(session.telemetry.home_position())
    return ACCEPTED


def _mission_start(session: GcsSession, cmd: CommandArgs) -> Result:
    ap = session.ap
    if not ap.armed:
        return failed("Mission start: vehicle not armed")
    first = whole(cmd.p(1), 0, UINT16_MAX)
    if first is None:
        return denied(f"Mission start: no item {cmd.p(1):g}")
    if first > 0 and not ap.mission.set_current(first):
        return denied(f"Mission start: no item {first}")
    if ap.mode == Mode.AUTO:
        ap.mission.start()
        return ACCEPTED
    return ap.set_mode(Mode.AUTO)


def _set_mission_current(session: GcsSession, cmd: CommandArgs) -> Result:
    seq = whole(cmd.p(1), 0, UINT16_MAX)
    if seq is None or not session.ap.mission.set_current(seq):
        return denied(f"Set mission current: no item {cmd.p(1):g}")
    return ACCEPTED


HANDLERS: dict[int, Handler] = {
    M.MAV_CMD_COMPONENT_ARM_DISARM: _arm_disarm,
    M.MAV_CMD_NAV_TAKEOFF: _takeoff,
    M.MAV_CMD_NAV_LAND: _land,
    M.MAV_CMD_NAV_RETURN_TO_LAUNCH: _rtl,
    M.MAV_CMD_DO_SET_MODE: _set_mode,
    M.MAV_CMD_CONDITION_YAW: _condition_yaw,
    M.MAV_CMD_DO_CHANGE_SPEED: _change_speed,
    M.MAV_CMD_DO_REPOSITION: _reposition,
    M.MAV_CMD_DO_MOUNT_CONTROL: _mount_control,
    M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW: _gimbal_pitchyaw,
    M.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE: _gimbal_configure,
    M.MAV_CMD_REQUEST_MESSAGE: _request_message,
    M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: _request_autopilot_version,
    M.MAV_CMD_SET_MESSAGE_INTERVAL: _set_message_interval,
    M.MAV_CMD_GET_MESSAGE_INTERVAL: _get_message_interval,
    M.MAV_CMD_GET_HOME_POSITION: _get_home,
    M.MAV_CMD_MISSION_START: _mission_start,
    M.MAV_CMD_DO_SET_MISSION_CURRENT: _set_mission_current,
    M.MAV_CMD_DO_DIGICAM_CONTROL: lambda session, cmd: (
        session.ap.shutter.trigger() if cmd.p(5) == 1 else ACCEPTED  # param5 1: shoot
    ),
    M.MAV_CMD_IMAGE_START_CAPTURE: lambda session, cmd: session.ap.shutter.trigger(),
    M.MAV_CMD_REQUEST_PROTOCOL_VERSION: lambda session, cmd: failed(
        "Protocol version: not provided"
    ),
}
