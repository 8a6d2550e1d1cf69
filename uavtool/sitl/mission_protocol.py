"""The MAVLink mission protocol, vehicle side: upload, download, clear, set current.

Only ``MAV_MISSION_TYPE_MISSION`` is stored; fence and rally transfers are refused with
``MAV_MISSION_UNSUPPORTED``. Item 0 is always home. Duplicated or out-of-order items and
lost requests are tolerated: the vehicle re-requests the item it needs, a few times.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from uavtool.mavlink.dialect import mavlink as M
from uavtool.sitl.args import UINT16_MAX, whole
from uavtool.sitl.auto import NAV_COMMANDS, SUPPORTED_COMMANDS
from uavtool.sitl.state import AMSL_FRAMES, MissionItem

if TYPE_CHECKING:
    from uavtool.sitl.gcs import GcsSession

_RETRY_NS = 1_500_000_000
_MAX_RETRIES = 5
# MISSION_ITEM (float) frames and their MISSION_ITEM_INT twins; items are stored as _INT.
_INT_FRAME = {
    M.MAV_FRAME_GLOBAL: M.MAV_FRAME_GLOBAL_INT,
    M.MAV_FRAME_GLOBAL_RELATIVE_ALT: M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
}
_FLOAT_FRAME = {v: k for k, v in _INT_FRAME.items()}
_AMSL = AMSL_FRAMES
_ALTITUDE_COMMANDS = frozenset({M.MAV_CMD_NAV_WAYPOINT, M.MAV_CMD_NAV_TAKEOFF})
_INT32_MAX = 2**31 - 1
_FRAMES = frozenset(
    {
        M.MAV_FRAME_GLOBAL,
        M.MAV_FRAME_GLOBAL_INT,
        M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        M.MAV_FRAME_MISSION,
    }
)


def _e7(value: float) -> int | None:
    """A MISSION_ITEM float x/y as MISSION_ITEM_INT stores it (×1e7), None if it cannot be."""
    if not math.isfinite(value) or abs(value) * 1e7 > _INT32_MAX:
        return None
    return round(value * 1e7)


class MissionProtocol:
    """One link's mission-transfer state."""

    def __init__(self, session: GcsSession) -> None:
        self.session = session
        self._upload: list[MissionItem] | None = None
        self._upload_count = 0
        self._upload_src = (0, 0)
        self._next_request_ns = 0
        self._retries = 0

    @property
    def _mission(self) -> Any:
        return self.session.ap.mission

    def _ack(self, result: int, mission_type: int = 0) -> None:
        sysid, compid = self._upload_src if self._upload is not None else self.session.last_source
        self.session.send(M.MAVLink_mission_ack_message(sysid, compid, result, mission_type))

    def home_item(self) -> MissionItem:
        home = self.session.ap.home
        return MissionItem(
            0,
            M.MAV_FRAME_GLOBAL_INT,
            M.MAV_CMD_NAV_WAYPOINT,
            0,
            1,
            0,
            0,
            0,
            0,
            home.lat_e7,
            home.lon_e7,
            home.alt_amsl_m,
        )

    def items(self) -> list[MissionItem]:
        stored = self._mission.items
        return stored if stored else [self.home_item()]

    def _refuse_type(self, msg: Any) -> None:
        """Fence and rally transfers: MAV_MISSION_UNSUPPORTED for that mission type."""
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        self.session.send(
            M.MAVLink_mission_ack_message(*src, M.MAV_MISSION_UNSUPPORTED, msg.mission_type)
        )

    # --------------------------------------------------------------- upload
    def on_count(self, msg: Any) -> None:
        if msg.mission_type != M.MAV_MISSION_TYPE_MISSION:
            self._refuse_type(msg)
            return
        if msg.count == 0:
            self._mission.replace([])
            self._ack(M.MAV_MISSION_ACCEPTED)
            return
        self._upload = []
        self._upload_count = msg.count
        self._upload_src = (msg.get_srcSystem(), msg.get_srcComponent())
        self._retries = 0
        self._request_next()

    def _request_next(self) -> None:
        assert self._upload is not None
        sysid, compid = self._upload_src
        self.session.send(
            M.MAVLink_mission_request_int_message(sysid, compid, len(self._upload), 0)
        )
        self._next_request_ns = self.session.ap.now_ns + _RETRY_NS

    def on_item(self, msg: Any, *, is_int: bool) -> None:
        if msg.mission_type != M.MAV_MISSION_TYPE_MISSION:
            return
        if self._upload is None:
            return  # a late duplicate after the transfer ended
        expected = len(self._upload)
        if msg.seq < expected:
            return  # duplicate of an item we already have
        if msg.seq > expected:
            self._request_next()
            return
        x, y = (msg.x, msg.y) if is_int else (_e7(msg.x), _e7(msg.y))
        frame = msg.frame
        if not is_int:  # the float frames map to their _INT twins
            frame = _INT_FRAME.get(frame, frame)
        if msg.seq == 0:  # item 0 is home, whatever was sent
            self._upload.append(self.home_item())
        else:
            error = self._item_error(msg, frame, x, y)
            if error is not None or x is None or y is None:
                self._ack(int(M.MAV_MISSION_ERROR) if error is None else error)
                self._upload = None
                return
            self._upload.append(
                MissionItem(
                    msg.seq,
                    frame,
                    msg.command,
                    msg.current,
                    msg.autocontinue,
                    msg.param1,
                    msg.param2,
                    msg.param3,
                    msg.param4,
                    x,
                    y,
                    msg.z,
                )
            )
        self._retries = 0
        if len(self._upload) < self._upload_count:
            self._request_next()
            return
        self._mission.replace(self._upload)
        self._ack(M.MAV_MISSION_ACCEPTED)
        self._upload = None

    def _item_error(self, msg: Any, frame: int, x: int | None, y: int | None) -> int | None:
        """The MAV_MISSION_RESULT refusing item ``msg`` (seq ≥ 1), or None if it can be flown."""
        cmd, p1, p4 = msg.command, msg.param1, msg.param4
        if cmd not in SUPPORTED_COMMANDS:
            return int(M.MAV_MISSION_UNSUPPORTED)
        if frame not in _FRAMES:
            return int(M.MAV_MISSION_UNSUPPORTED_FRAME)
        if x is None or (frame != M.MAV_FRAME_MISSION and abs(x) > 90 * 10**7):
            return int(M.MAV_MISSION_INVALID_PARAM5_X)
        if y is None or (frame != M.MAV_FRAME_MISSION and abs(y) > 180 * 10**7):
            return int(M.MAV_MISSION_INVALID_PARAM6_Y)
        if cmd in NAV_COMMANDS and not math.isfinite(msg.z):
            return int(M.MAV_MISSION_INVALID_PARAM7)
        alt_m = msg.z - self.session.ap.home.alt_amsl_m if frame in _AMSL else msg.z
        if cmd in _ALTITUDE_COMMANDS and alt_m < 0.0:  # a target below ground
            return int(M.MAV_MISSION_INVALID_PARAM7)
        if cmd == M.MAV_CMD_NAV_WAYPOINT and not 0.0 <= p1 <= UINT16_MAX:  # hold time, s
            return int(M.MAV_MISSION_INVALID_PARAM1)
        if cmd == M.MAV_CMD_DO_CHANGE_SPEED and (
            whole(p1, 0, 3) is None or not math.isfinite(msg.param2)
        ):
            return int(M.MAV_MISSION_INVALID_PARAM1)
        if cmd == M.MAV_CMD_CONDITION_YAW and not (0.0 <= p1 <= 360.0 and p4 in (0.0, 1.0)):
            return int(M.MAV_MISSION_INVALID_PARAM1)
        return None

    def tick(self, now_ns: int) -> None:
        if self._upload is None or now_ns < self._next_request_ns:
            return
        self._retries += 1
        if self._retries > _MAX_RETRIES:
            self._ack(M.MAV_MISSION_OPERATION_CANCELLED)
            self._upload = None
            return
        self._request_next()

    # --------------------------------------------------------------- download, clear
    def on_request_list(self, msg: Any) -> None:
        if msg.mission_type != M.MAV_MISSION_TYPE_MISSION:
            self._refuse_type(msg)
            return
        self.session.send(
            M.MAVLink_mission_count_message(
                msg.get_srcSystem(), msg.get_srcComponent(), len(self.items()), 0
            )
        )

    def on_request(self, msg: Any, *, is_int: bool) -> None:
        if msg.mission_type != M.MAV_MISSION_TYPE_MISSION:
            return
        items = self.items()
        if not 0 <= msg.seq < len(items):
            self.session.send(
                M.MAVLink_mission_ack_message(
                    msg.get_srcSystem(), msg.get_srcComponent(), M.MAV_MISSION_INVALID_SEQUENCE, 0
                )
            )
            return
        it = items[msg.seq]
        current = 1 if it.seq == self._mission.current else 0
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if is_int:
            out = M.MAVLink_mission_item_int_message(
                *src,
                it.seq,
                it.frame,
                it.command,
                current,
                it.autocontinue,
                it.param1,
                it.param2,
                it.param3,
                it.param4,
                it.x,
                it.y,
                it.z,
                0,
            )
        else:
            frame = _FLOAT_FRAME.get(it.frame, it.frame)
            out = M.MAVLink_mission_item_message(
                *src,
                it.seq,
                frame,
                it.command,
                current,
                it.autocontinue,
                it.param1,
                it.param2,
                it.param3,
                it.param4,
                it.x / 1e7,
                it.y / 1e7,
                it.z,
                0,
            )
        self.session.send(out)

    def on_clear_all(self, msg: Any) -> None:
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if msg.mission_type not in (M.MAV_MISSION_TYPE_MISSION, M.MAV_MISSION_TYPE_ALL):
            self.session.send(
                M.MAVLink_mission_ack_message(*src, M.MAV_MISSION_UNSUPPORTED, msg.mission_type)
            )
            return
        self._mission.replace([])
        self.session.send(
            M.MAVLink_mission_ack_message(*src, M.MAV_MISSION_ACCEPTED, msg.mission_type)
        )

    def on_set_current(self, msg: Any) -> None:
        if self._mission.set_current(msg.seq):
            self.session.send(self.session.telemetry.mission_current())
