"""The ground-station side of a MAVLink link: one adapter around pymavlink for every vehicle
(the built-in SITL, ArduPilot's SITL, a real ArduCopter). It only uses what ArduPilot does:
HEARTBEAT custom modes, COMMAND_LONG with COMMAND_ACK, SET_POSITION_TARGET_GLOBAL_INT,
SET_MESSAGE_INTERVAL, HOME_POSITION and the gimbal/mount status messages."""

from __future__ import annotations

import math
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from uavtool.camera import CameraPose, Quaternion, camera_from_attitude
from uavtool.errors import InputError, LinkError
from uavtool.geo import GeoPoint, wrap_180
from uavtool.link.freshness import FreshnessFilter
from uavtool.link.transport import Transport
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mavlink.framing import Frame, FrameParser, new_encoder
from uavtool.mavlink.packing import pack

GCS_SYSID = 255
GCS_COMPID = M.MAV_COMP_ID_MISSIONPLANNER
ANNOUNCE_S = 1.0
"""How often a link that has not heard a vehicle yet sends its heartbeat (MAVProxy's rate)."""
Tap = Callable[[str, list[bytes], list[Any] | None], None]
"""Called with ``("in" | "out", frames' bytes, messages)`` for the whole frames that cross
the link, once per read (several frames) or send (one): for incoming frames, the pymavlink
messages the link decoded from those bytes (in :data:`~uavtool.mavlink.dialect.DIALECT`),
one per frame; None for outgoing ones. A read's frames arrived together: a recording stamps
them with one time (and a flight taps ~14,000 frames in ~2,600 reads)."""

# What the runner needs, and how often (Hz); requested with SET_MESSAGE_INTERVAL.
STREAMS: dict[int, float] = {
    M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: 10.0,
    M.MAVLINK_MSG_ID_ATTITUDE: 10.0,
    M.MAVLINK_MSG_ID_SYS_STATUS: 1.0,
    M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: 2.0,
    M.MAVLINK_MSG_ID_GIMBAL_DEVICE_ATTITUDE_STATUS: 10.0,
    M.MAVLINK_MSG_ID_MOUNT_STATUS: 10.0,
    M.MAVLINK_MSG_ID_HOME_POSITION: 0.5,
}
_NOT_VEHICLES = {M.MAV_TYPE_GCS, M.MAV_TYPE_GIMBAL, M.MAV_TYPE_ONBOARD_CONTROLLER}
_GIMBAL_KEY = struct.Struct("<5dQ")  # a gimbal status's quaternion, the heading, its flags
_GIMBAL_KEPT = 1024


@dataclass(slots=True)
class VehicleState:
    """The latest of each message the vehicle sent (pymavlink message objects)."""

    heartbeat: Any = None
    position: Any = None  # GLOBAL_POSITION_INT
    attitude: Any = None
    extended: Any = None  # EXTENDED_SYS_STATE
    sys_status: Any = None
    gimbal_pitch_deg: float | None = None
    gimbal_yaw_deg: float | None = None
    """The camera's pitch from the horizon and yaw from the nose, wrapped to ±180°, as the
    gimbal reports them (from its whole quaternion, see :func:`gimbal_camera_pose`)."""
    gimbal: Any = None  # GIMBAL_DEVICE_ATTITUDE_STATUS
    home: GeoPoint | None = None
    statustext: list[tuple[int, str]] = field(default_factory=list)


Clock = Callable[[], float]
"""Seconds on the link's clock: the wall clock (``time.monotonic``) for a vehicle that flies
in real time, the vehicle's own clock for one stepped in lockstep."""


class VehicleLink:
    """A connection to one vehicle. ``poll`` reads what arrived and returns the messages from
    the vehicle, stale ones left out (``freshness`` counts them); ``send`` packs and sends.
    ``clock`` is what every wait on this link is timed by. ``tap`` hears every frame, stale or
    not. With ``announce`` the link sends its heartbeat before it has heard a vehicle, as
    MAVProxy and MAVSDK do: a vehicle listening on UDP learns from it where to send. Not
    thread-safe (the runner owns it)."""

    def __init__(
        self,
        transport: Transport,
        *,
        tap: Tap | None = None,
        clock: Clock = time.monotonic,
        announce: bool = True,
        encoder: Any = None,
    ) -> None:
        """``encoder``: the pymavlink encoder (its sequence) to send with, shared by links that
        send on one transport (`uavtool.recorder.fleet.FleetLink`); None: one of its own."""
        self.transport = transport
        self.clock = clock
        self.name = transport.name
        self.tap = tap
        self.announce = announce
        self.freshness = FreshnessFilter()
        self._parser = FrameParser()
        self._gimbal_seen: dict[bytes, tuple[float, float]] = {}  # see _gimbal_angles_of
        self._mav = (
            encoder if encoder is not None else new_encoder(sysid=GCS_SYSID, compid=GCS_COMPID)
        )
        self.target_system = 0
        self.target_component = 0
        self.state = VehicleState()

    def close(self) -> None:
        self.transport.close()

    # --- receiving ----------------------------------------------------------------------------

    def poll(self, timeout_s: float) -> list[Any]:
        """Messages from the vehicle received within ``timeout_s`` (one read)."""
        data = self.transport.recv(timeout_s)
        if not data:
            return []
        frames = self._parser.feed(data)
        if self.tap is not None and frames:
            self.tap("in", [frame.raw for frame in frames], [frame.msg for frame in frames])
        return self.take(frames)

    def take(self, frames: list[Frame]) -> list[Any]:
        """The messages of ``frames`` (read and tapped by ``poll``, or by a reader that shares
        one link among several vehicles) that are from the vehicle and fresh; the state is
        updated with them."""
        out = []
        for frame in frames:
            msg = frame.msg
            if self._accept(msg) and self.freshness.fresh(msg):
                self._update(msg)
                out.append(msg)
        return out

    def _accept(self, msg: Any) -> bool:
        sysid = msg.get_srcSystem()
        if self.target_system == 0:
            if not is_vehicle_heartbeat(msg):
                return False
            self.target_system = sysid
            self.target_component = msg.get_srcComponent()
        return bool(sysid == self.target_system)

    def _update(self, msg: Any) -> None:
        s = self.state
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            if msg.get_srcComponent() == self.target_component:
                s.heartbeat = msg
        elif kind == "GLOBAL_POSITION_INT":
            s.position = msg
        elif kind == "ATTITUDE":
            s.attitude = msg
        elif kind == "EXTENDED_SYS_STATE":
            s.extended = msg
        elif kind == "SYS_STATUS":
            s.sys_status = msg
        elif kind == "HOME_POSITION":
            s.home = GeoPoint(msg.latitude / 1e7, msg.longitude / 1e7, msg.altitude / 1000.0)
        elif kind == "GIMBAL_DEVICE_ATTITUDE_STATUS":
            s.gimbal = msg
            s.gimbal_pitch_deg, s.gimbal_yaw_deg = self._gimbal_angles_of(msg, _heading_deg(s))
        elif kind == "MOUNT_STATUS":
            s.gimbal_pitch_deg, s.gimbal_yaw_deg = msg.pointing_a / 100.0, msg.pointing_c / 100.0
        elif kind == "STATUSTEXT":
            s.statustext.append((msg.severity, msg.text))

    def _gimbal_angles_of(self, msg: Any, vehicle_heading_deg: float) -> tuple[float, float]:
        """`_gimbal_angles`, remembered: a steady gimbal sends the same quaternion and flags
        ten times a second, and the heading holds (the paper flight: 2,282 statuses, 28
        different). Keyed by the numbers' exact bits (-0.0 is not 0.0, and gives another
        sign)."""
        try:
            q = msg.q
            key = _GIMBAL_KEY.pack(q[0], q[1], q[2], q[3], vehicle_heading_deg, msg.flags)
        except (struct.error, TypeError, IndexError):
            return _gimbal_angles(msg, vehicle_heading_deg)
        angles = self._gimbal_seen.get(key)
        if angles is None:
            if len(self._gimbal_seen) >= _GIMBAL_KEPT:
                self._gimbal_seen.clear()
            angles = self._gimbal_seen[key] = _gimbal_angles(msg, vehicle_heading_deg)
        return angles

    # --- sending ------------------------------------------------------------------------------

    def send(self, msg: Any) -> None:
        frame = pack(msg, self._mav)
        self._mav.seq = (self._mav.seq + 1) % 256
        if self.tap is not None:
            self.tap("out", [frame], None)
        self.transport.send(frame)

    def heartbeat(self) -> None:
        self.send(M.MAVLink_heartbeat_message(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0, 3))

    def command_long(self, command: int, *params: float) -> None:
        args = [*params, *([0.0] * (7 - len(params)))]
        self.send(
            M.MAVLink_command_long_message(
                self.target_system, self.target_component, command, 0, *args
            )
        )

    def request_streams(self) -> None:
        """Ask for the messages the runner uses (ArduPilot honours SET_MESSAGE_INTERVAL)."""
        for msgid, hz in STREAMS.items():
            self.command_long(M.MAV_CMD_SET_MESSAGE_INTERVAL, msgid, 1e6 / hz)
        self.command_long(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_HOME_POSITION)

    def wait_vehicle(self, timeout_s: float, *, on_wait: Callable[[], None] | None = None) -> None:
        """Block until a vehicle's heartbeat and home position are known (``timeout_s`` on the
        link's clock); LinkError if not."""
        deadline = self.clock() + timeout_s
        last_request: float | None = None
        last_announce: float | None = None
        while self.state.home is None or self.state.position is None or last_request is None:
            now = self.clock()
            if now > deadline:
                what = "heartbeat" if self.target_system == 0 else "home position"
                raise LinkError(f"{self.name}: no {what} from a vehicle in {timeout_s:g} s")
            if self.target_system:
                if last_request is None or now - last_request > 2.0:
                    self.heartbeat()
                    self.request_streams()
                    last_request = now
            elif self.announce and (last_announce is None or now - last_announce >= ANNOUNCE_S):
                self.heartbeat()
                last_announce = now
            if on_wait is not None:
                on_wait()
            self.poll(0.05)


def is_vehicle_heartbeat(msg: Any) -> bool:
    """Whether ``msg`` is a vehicle's HEARTBEAT: not a ground station's, a gimbal's or a
    companion computer's, and from an autopilot (what a link locks onto)."""
    return bool(
        msg.get_type() == "HEARTBEAT"
        and msg.type not in _NOT_VEHICLES
        and msg.autopilot != M.MAV_AUTOPILOT_INVALID
    )


def gimbal_camera_pose(
    msg: Any, *, pos_enu_m: tuple[float, float, float], vehicle_heading_deg: float
) -> CameraPose | None:
    """The camera's pose from a GIMBAL_DEVICE_ATTITUDE_STATUS: its whole quaternion composed
    with the vehicle's heading when its flags say the yaw is in the vehicle frame (ArduPilot
    always does), taken as it is in the earth frame; None when the quaternion is unknown."""
    q: Quaternion = (float(msg.q[0]), float(msg.q[1]), float(msg.q[2]), float(msg.q[3]))
    try:
        return camera_from_attitude(
            pos_enu_m,
            vehicle_heading_deg=vehicle_heading_deg,
            gimbal_q=q,
            yaw_in_vehicle_frame=_yaw_in_vehicle_frame(int(msg.flags)),
        )
    except InputError:
        return None


def _yaw_in_vehicle_frame(flags: int) -> bool:
    if flags & M.GIMBAL_DEVICE_FLAGS_YAW_IN_VEHICLE_FRAME:
        return True
    if flags & M.GIMBAL_DEVICE_FLAGS_YAW_IN_EARTH_FRAME:
        return False
    return not flags & M.GIMBAL_DEVICE_FLAGS_YAW_LOCK  # MAVLink's rule when neither is set


def _heading_deg(s: VehicleState) -> float:
    if s.position is not None and s.position.hdg != 65535:
        return float(s.position.hdg) / 100.0
    return math.degrees(s.attitude.yaw) % 360.0 if s.attitude is not None else 0.0


def _gimbal_angles(msg: Any, vehicle_heading_deg: float) -> tuple[float, float]:
    """(pitch from the horizon, yaw from the nose wrapped to ±180) in degrees; NaN when the
    gimbal does not know its attitude."""
    pose = gimbal_camera_pose(
        msg, pos_enu_m=(0.0, 0.0, 0.0), vehicle_heading_deg=vehicle_heading_deg
    )
    if pose is None:
        return math.nan, math.nan
    return pose.pitch_deg, wrap_180(pose.heading_deg - vehicle_heading_deg)
