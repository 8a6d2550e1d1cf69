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
    force = round(cmd.p(2)) == FORCE_MAGIC
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
    if not int(cmd.p(1)) & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
        return denied("Set mode: only custom (ArduCopter) modes are supported")
    return session.set_mode_number(int(cmd.p(2)))


def _condition_yaw(session: GcsSession, cmd: CommandArgs) -> Result:
    return session.ap.condition_yaw(cmd.p(1), cmd.p(2), int(cmd.p(3)), cmd.p(4) != 0.0)


def _change_speed(session: GcsSession, cmd: CommandArgs) -> Result:
    return session.ap.change_speed(int(cmd.p(1)), cmd.p(2))


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
    if not (math.isfinite(lat) and math.isfinite(lon) and math.isfinite(alt_rel)):
        return denied("Reposition: position must be finite")
    n, e, _ = ap.ned_of(GeoPoint(lat, lon, ap.home.alt_amsl_m))
    if cmd.p(1) > 0:
        ap.change_speed(1, cmd.p(1))
    # param4 (yaw) is ignored, as ArduCopter does: clients disagree on its unit (MAVSDK
    # sends radians, the spec says degrees); yaw is set with CONDITION_YAW or a target.
    change_mode = bool(int(cmd.p(2)) & M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE)
    return ap.guided_position((n, e, -alt_rel), switch_mode=change_mode)


def _mount_control(session: GcsSession, cmd: CommandArgs) -> Result:
    # param1 pitch, param3 yaw (body frame), degrees; param7 mount mode.
    return session.ap.set_gimbal(pitch_deg=cmd.p(1), yaw_deg=cmd.p(3))


def _gimbal_pitchyaw(session: GcsSession, cmd: CommandArgs) -> Result:
    device = int(cmd.p(7))
    if device not in (0, 1):
        return denied(f"Gimbal: no gimbal device {device}")
    flags = int(cmd.p(5)) if math.isfinite(cmd.p(5)) else 0
    locked = bool(flags & M.GIMBAL_MANAGER_FLAGS_YAW_LOCK)
    return session.ap.set_gimbal(pitch_deg=cmd.p(1), yaw_deg=cmd.p(2), yaw_locked=locked)


def _gimbal_configure(session: GcsSession, cmd: CommandArgs) -> Result:
    sysid = int(cmd.p(1))
    compid = int(cmd.p(2))
    if sysid == -2:  # "the sender takes control"
        sysid, compid = cmd.source
    session.ap.gimbal_owner = (max(sysid, 0), max(compid, 0))
    return ACCEPTED


def _request_message(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = int(cmd.p(1))
    msg = session.telemetry.build(msg_id)
    if msg is None:
        return failed(f"Request message: message {msg_id} is not available")
    session.defer(msg)  # sent right after the ACK
    return ACCEPTED


def _request_autopilot_version(session: GcsSession, cmd: CommandArgs) -> Result:
    session.defer(session.telemetry.autopilot_version())
    return ACCEPTED


def _set_message_interval(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = int(cmd.p(1))
    if session.telemetry.builders.get(msg_id) is None:
        return failed(f"Set message interval: message {msg_id} is not streamed")
    session.streams.set_interval(msg_id, cmd.p(2), session.ap.now_ns)
    return ACCEPTED


def _get_message_interval(session: GcsSession, cmd: CommandArgs) -> Result:
    msg_id = int(cmd.p(1))
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
    first = int(cmd.p(1))
    if first > 0 and not ap.mission.set_current(first):
        return denied(f"Mission start: no item {first}")
    if ap.mode == Mode.AUTO:
        ap.mission.start()
        return ACCEPTED
    return ap.set_mode(Mode.AUTO)


def _set_mission_current(session: GcsSession, cmd: CommandArgs) -> Result:
    seq = int(cmd.p(1))
    if not session.ap.mission.set_current(seq):
        return denied(f"Set mission current: no item {seq}")
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
    M.MAV_CMD_REQUEST_PROTOCOL_VERSION: lambda session, cmd: failed(
        "Protocol version: not provided"
    ),
}
