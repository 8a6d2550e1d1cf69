"""The vehicle side of one MAVLink link: dispatches what a ground station sends.

A :class:`GcsSession` serves one peer (one TCP connection, one UDP address): commands and
their ACKs, the parameter and mission protocols, guided position targets, gimbal control,
stream-rate requests, and a NAK for MAVLink FTP so clients fall back to the parameter
protocol at once.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from uavtool.errors import ParamError
from uavtool.geo import GeoPoint
from uavtool.mavlink.dialect import mavlink as M
from uavtool.sitl.args import lat_lon_ok
from uavtool.sitl.commands import HANDLERS, CommandArgs
from uavtool.sitl.mission_protocol import MissionProtocol
from uavtool.sitl.state import (
    ACCEPTED,
    AMSL_FRAMES,
    RELATIVE_ALT_FRAMES,
    Mode,
    Result,
    denied,
    failed,
)
from uavtool.sitl.telemetry import DATA_STREAMS, Streams

if TYPE_CHECKING:
    from uavtool.mavlink.framing import Frame
    from uavtool.sitl.autopilot import Autopilot
    from uavtool.sitl.links import Link
    from uavtool.sitl.server import Sitl
    from uavtool.sitl.telemetry import Telemetry

log = logging.getLogger(__name__)

# Unsigned messages ArduPilot still accepts when signing is on (radio modems inject these).
_UNSIGNED_OK = frozenset({M.MAVLINK_MSG_ID_RADIO_STATUS, M.MAVLINK_MSG_ID_RADIO})
_FTP_NAK = 129
_FTP_OPEN_RO = 4
_FTP_ERR_FILE_NOT_FOUND = 10
_FTP_ERR_UNKNOWN_COMMAND = 7
_TM_POS = 0b111
_TM_VEL = 0b111000
_TM_YAW = 1024


class GcsSession:
    """Everything the vehicle does for one connected peer."""

    def __init__(self, sitl: Sitl, link: Link) -> None:
        self.sitl = sitl
        self.link = link
        self.ap: Autopilot = sitl.autopilot
        self.telemetry: Telemetry = sitl.telemetry
        self.streams = Streams()
        self.missions = MissionProtocol(self)
        self.last_source = (0, 0)
        self.rejected_unsigned = 0
        self._deferred: list[Any] = []
        self._handlers: dict[str, Callable[[Any], None]] = {
            "HEARTBEAT": self._on_heartbeat,
            "COMMAND_LONG": self._on_command_long,
            "COMMAND_INT": self._on_command_int,
            "SET_MODE": self._on_set_mode,
            "PARAM_REQUEST_LIST": self._on_param_request_list,
            "PARAM_REQUEST_READ": self._on_param_request_read,
            "PARAM_SET": self._on_param_set,
            "MISSION_COUNT": self.missions.on_count,
            "MISSION_ITEM_INT": lambda m: self.missions.on_item(m, is_int=True),
            "MISSION_ITEM": lambda m: self.missions.on_item(m, is_int=False),
            "MISSION_REQUEST_LIST": self.missions.on_request_list,
            "MISSION_REQUEST_INT": lambda m: self.missions.on_request(m, is_int=True),
            "MISSION_REQUEST": lambda m: self.missions.on_request(m, is_int=False),
            "MISSION_CLEAR_ALL": self.missions.on_clear_all,
            "MISSION_SET_CURRENT": self.missions.on_set_current,
            "SET_POSITION_TARGET_LOCAL_NED": self._on_position_target_local,
            "SET_POSITION_TARGET_GLOBAL_INT": self._on_position_target_global,
            "GIMBAL_MANAGER_SET_ATTITUDE": self._on_gimbal_set_attitude,
            "REQUEST_DATA_STREAM": self._on_request_data_stream,
            "FILE_TRANSFER_PROTOCOL": self._on_ftp,
        }

    # ------------------------------------------------------------------ plumbing
    def send(self, msg: Any) -> None:
        self.link.send(msg)

    def defer(self, msg: Any) -> None:
        """Send ``msg`` after the COMMAND_ACK of the command being handled."""
        self._deferred.append(msg)

    def handle(self, frame: Frame) -> None:
        msg = frame.msg
        signing = self.sitl.signing
        verified = signing is None or signing.verify(frame.raw)
        if not verified and msg.get_msgId() not in _UNSIGNED_OK:
            self.rejected_unsigned += 1
            return
        if verified:  # with a key, an unsigned radio report never holds a UDP peer's place
            self.link.heard(time.monotonic_ns())
        handler = self._handlers.get(msg.get_type())
        if handler is None or not self._addressed_to_us(msg):
            return
        self.last_source = (msg.get_srcSystem(), msg.get_srcComponent())
        handler(msg)  # an exception is the server's to log, count and isolate

    def _addressed_to_us(self, msg: Any) -> bool:
        target = getattr(msg, "target_system", 0)
        if target not in (0, self.sitl.sysid):
            return False
        comp = getattr(msg, "target_component", 0)
        return comp in (0, self.sitl.compid)

    def tick(self, now_ns: int) -> None:
        """Send due telemetry; retry mission transfers."""
        self.missions.tick(now_ns)
        for msg_id in self.streams.due(now_ns):
            msg = self.telemetry.build(msg_id)
            if msg is not None:
                self.send(msg)

    def statustext(self, severity: int, text: str) -> None:
        self.send(M.MAVLink_statustext_message(severity, text.encode()[:50]))

    # ------------------------------------------------------------------ commands
    def _on_command_long(self, msg: Any) -> None:
        params = (
            msg.param1,
            msg.param2,
            msg.param3,
            msg.param4,
            msg.param5,
            msg.param6,
            msg.param7,
        )
        self._run_command(CommandArgs(msg.command, params, None, 0, 0, self.last_source))

    def _on_command_int(self, msg: Any) -> None:
        params = (msg.param1, msg.param2, msg.param3, msg.param4, float(msg.x), float(msg.y), msg.z)
        self._run_command(
            CommandArgs(msg.command, params, msg.frame, msg.x, msg.y, self.last_source)
        )

    def _run_command(self, cmd: CommandArgs) -> None:
        handler = HANDLERS.get(cmd.command)
        self._deferred = []
        try:
            result = Result(M.MAV_RESULT_UNSUPPORTED) if handler is None else handler(self, cmd)
        except Exception:  # refuse this request; the vehicle and other links go on
            self.sitl.fault(self.link, f"command {cmd.command}")
            result, self._deferred = failed(f"Command {cmd.command}: internal error"), []
        sysid, compid = cmd.source
        if result.reason:  # before the ACK, as ArduPilot: a client reading the ACK has it
            self.statustext(M.MAV_SEVERITY_WARNING, result.reason)
        self.send(M.MAVLink_command_ack_message(cmd.command, result.code, 0, 0, sysid, compid))
        for deferred in self._deferred:
            self.send(deferred)
        self._deferred = []

    def set_mode_number(self, number: int) -> Result:
        try:
            mode = Mode(number)
        except ValueError:
            return denied(f"Mode {number} is not supported by this vehicle")
        return self.ap.set_mode(mode)

    def _on_set_mode(self, msg: Any) -> None:
        if not msg.base_mode & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            result = denied("Set mode: only custom (ArduCopter) modes are supported")
        else:
            result = self.set_mode_number(msg.custom_mode)
        sysid, compid = self.last_source
        self.send(
            M.MAVLink_command_ack_message(
                M.MAVLINK_MSG_ID_SET_MODE, result.code, 0, 0, sysid, compid
            )
        )
        if result.reason:
            self.statustext(M.MAV_SEVERITY_WARNING, result.reason)

    def _on_heartbeat(self, msg: Any) -> None:
        if msg.type == M.MAV_TYPE_GCS:
            self.ap.gcs_heartbeat()

    # ------------------------------------------------------------------ parameters
    def _param_value(self, name: str) -> Any:
        params = self.ap.params
        return M.MAVLink_param_value_message(
            name.encode(), params[name], params.mav_type(name), len(params), params.index(name)
        )

    def _on_param_request_list(self, msg: Any) -> None:  # noqa: ARG002 - handler signature
        for name in self.ap.params.names():
            self.send(self._param_value(name))

    def _on_param_request_read(self, msg: Any) -> None:
        name = msg.param_id if msg.param_index < 0 else self.ap.params.name_at(msg.param_index)
        if name is None or name not in self.ap.params:
            return  # ArduPilot stays silent for unknown parameters
        self.send(self._param_value(name))

    def _on_param_set(self, msg: Any) -> None:
        name = msg.param_id
        try:
            self.sitl.set_param(name, msg.param_value)
        except ParamError as exc:
            self.statustext(M.MAV_SEVERITY_WARNING, str(exc))
            if name in self.ap.params:  # as ArduPilot: answer with the value it kept
                self.send(self._param_value(name))
            return
        self.sitl.broadcast(self._param_value(name))

    # ------------------------------------------------------------------ guided targets
    def _on_position_target_local(self, msg: Any) -> None:
        ap = self.ap
        mask, frame = msg.type_mask, msg.coordinate_frame
        n, e, d = ap.state.pos_ned_m
        yaw_now = ap.state.yaw_deg
        if frame == M.MAV_FRAME_LOCAL_NED:
            pos = (msg.x, msg.y, msg.z)
            vel = (msg.vx, msg.vy, msg.vz)
        elif frame == M.MAV_FRAME_LOCAL_OFFSET_NED:
            pos = (n + msg.x, e + msg.y, d + msg.z)
            vel = (msg.vx, msg.vy, msg.vz)
        elif frame in (M.MAV_FRAME_BODY_NED, M.MAV_FRAME_BODY_OFFSET_NED):
            c, s = math.cos(math.radians(yaw_now)), math.sin(math.radians(yaw_now))
            dx, dy = msg.x * c - msg.y * s, msg.x * s + msg.y * c
            pos = (n + dx, e + dy, d + msg.z)
            vel = (msg.vx * c - msg.vy * s, msg.vx * s + msg.vy * c, msg.vz)
        else:
            self.statustext(M.MAV_SEVERITY_WARNING, f"Guided: unsupported frame {frame}")
            return
        self._apply_target(mask, pos, vel, msg.yaw)

    def _on_position_target_global(self, msg: Any) -> None:
        ap = self.ap
        mask, frame = msg.type_mask, msg.coordinate_frame
        if frame in AMSL_FRAMES:
            alt_rel = msg.alt - ap.home.alt_amsl_m
        elif frame in RELATIVE_ALT_FRAMES or frame == M.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT:
            alt_rel = msg.alt  # flat terrain: above terrain is above home
        else:
            self.statustext(M.MAV_SEVERITY_WARNING, f"Guided: unsupported frame {frame}")
            return
        lat, lon = msg.lat_int / 1e7, msg.lon_int / 1e7
        if not lat_lon_ok(lat, lon):
            if not mask & _TM_POS:
                self.statustext(M.MAV_SEVERITY_WARNING, "Guided: no such position")
                return
            lat, lon = ap.home.lat_deg, ap.home.lon_deg  # ignored: a velocity or yaw target
        n, e, _ = ap.ned_of(GeoPoint(lat, lon, ap.home.alt_amsl_m))
        self._apply_target(mask, (n, e, -alt_rel), (msg.vx, msg.vy, msg.vz), msg.yaw)

    def _apply_target(
        self,
        mask: int,
        pos: tuple[float, float, float],
        vel: tuple[float, float, float],
        yaw_rad: float,
    ) -> None:
        yaw = (
            None if mask & _TM_YAW or not math.isfinite(yaw_rad) else math.degrees(yaw_rad) % 360.0
        )
        if not mask & _TM_POS:
            result = self.ap.guided_position(pos, yaw_deg=yaw)
        elif not mask & _TM_VEL:
            result = self.ap.guided_velocity(vel, yaw_deg=yaw)
        else:
            result = ACCEPTED if yaw is None else self.ap.condition_yaw(yaw, 0.0, 0, False)
        if result.code == M.MAV_RESULT_DENIED and result.reason:
            self.statustext(M.MAV_SEVERITY_WARNING, result.reason)

    # ------------------------------------------------------------------ gimbal, streams, FTP
    def _on_gimbal_set_attitude(self, msg: Any) -> None:
        w, x, y, z = msg.q
        if not all(math.isfinite(v) for v in (w, x, y, z)):
            return
        pitch = math.degrees(math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x)))))
        yaw = math.degrees(math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
        locked = bool(msg.flags & M.GIMBAL_MANAGER_FLAGS_YAW_LOCK)
        self.ap.set_gimbal(pitch_deg=pitch, yaw_deg=yaw, yaw_locked=locked)

    def _on_request_data_stream(self, msg: Any) -> None:
        now = self.ap.now_ns
        rate = msg.req_message_rate if msg.start_stop else 0
        groups = (
            DATA_STREAMS.values()
            if msg.req_stream_id == M.MAV_DATA_STREAM_ALL
            else (DATA_STREAMS.get(msg.req_stream_id, ()),)
        )
        for group in groups:
            for msg_id in group:
                self.streams.set_rate_hz(msg_id, rate, now)

    def _on_ftp(self, msg: Any) -> None:
        payload = bytes(msg.payload)
        if len(payload) < 12:
            return
        opcode = payload[3]
        error = _FTP_ERR_FILE_NOT_FOUND if opcode == _FTP_OPEN_RO else _FTP_ERR_UNKNOWN_COMMAND
        reply = bytearray(251)
        seq = (int.from_bytes(payload[0:2], "little") + 1) & 0xFFFF
        reply[0:2] = seq.to_bytes(2, "little")  # a reply carries the request's seq + 1
        reply[2] = payload[2]  # session
        reply[3] = _FTP_NAK
        reply[4] = 1  # data size
        reply[5] = opcode  # req_opcode
        reply[12] = error
        sysid, compid = self.last_source
        self.send(M.MAVLink_file_transfer_protocol_message(0, sysid, compid, list(reply)))
