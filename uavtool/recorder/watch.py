"""What a passive recorder learns from the link besides telemetry: events worth a line in the
log (mode changes, arming, STATUSTEXT, mission progress, other ground stations), photo
triggers, and whether the flight is over.

Photo triggers, from any system and either direction: ``COMMAND_LONG`` / ``COMMAND_INT``
``IMAGE_START_CAPTURE``, or ``DO_DIGICAM_CONTROL`` with its shot parameter (param5) 1; the
vehicle's ``COMMAND_ACK`` accepting ``IMAGE_START_CAPTURE``; ``CAMERA_FEEDBACK`` and
``CAMERA_TRIGGER`` (the autopilot's own camera, e.g. an AUTO mission's DO_DIGICAM_CONTROL
item). One shutter is often seen several ways (the command, its ACK, the feedback), so
triggers less than ``TRIGGER_MERGE_S`` apart make one photo.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from uavtool.autopilot import Autopilot, for_vehicle
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mavlink.framing import FrameParser
from uavtool.recording import LogLevel

TRIGGER_MERGE_S = 0.5
OTHER_GCS_S = 5.0
"""A ground station counts as present for this long after its last heartbeat."""
_CAMERA_COMMANDS = {M.MAV_CMD_IMAGE_START_CAPTURE, M.MAV_CMD_DO_DIGICAM_CONTROL}
# Message ids worth decoding when another system sends them (the rest is only recorded).
_FOREIGN_IDS = {
    M.MAVLINK_MSG_ID_HEARTBEAT,
    M.MAVLINK_MSG_ID_COMMAND_LONG,
    M.MAVLINK_MSG_ID_COMMAND_INT,
}
_SEVERITY = {
    0: LogLevel.FATAL,
    1: LogLevel.FATAL,
    2: LogLevel.ERROR,
    3: LogLevel.ERROR,
    4: LogLevel.WARNING,
    5: LogLevel.INFO,
    6: LogLevel.INFO,
    7: LogLevel.DEBUG,
}


@dataclass(frozen=True, slots=True)
class Event:
    level: LogLevel
    text: str
    source: str = "vehicle"


def frame_ids(raw: bytes) -> tuple[int, int]:
    """``(sysid, msgid)`` from a whole MAVLink 1 or 2 frame's header."""
    if raw[0] == 0xFD:
        return raw[5], raw[7] | raw[8] << 8 | raw[9] << 16
    return raw[3], raw[5]


class VehicleWatch:
    """Fed every message of the vehicle (``vehicle``) and every frame of another system
    (``foreign``); collects events and photo triggers. ``now_s`` is the link's clock.
    ``addressed``: a camera command counts only when addressed to this vehicle (or to all),
    as on a link that carries a fleet."""

    def __init__(
        self, target_system: int, target_component: int, *, addressed: bool = False
    ) -> None:
        self.target = (target_system, target_component)
        self.addressed = addressed
        self.events: list[Event] = []
        self.triggers: list[str] = []
        self.other_gcs: dict[int, float] = {}  # sysid -> when last heard
        self._parser = FrameParser()
        self._mode: tuple[int, bool] | None = None
        self.autopilot: Autopilot | None = None
        """The vehicle's autopilot, known from its first HEARTBEAT."""
        self._mission_seq: int | None = None
        self._last_trigger_s: float | None = None
        self.airborne_seen = False

    # --- input ----------------------------------------------------------------------------

    def vehicle(self, msg: Any, now_s: float) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT" and msg.get_srcComponent() == self.target[1]:
            self._heartbeat(msg)
        elif kind == "STATUSTEXT":
            self.events.append(Event(_SEVERITY.get(msg.severity, LogLevel.INFO), msg.text))
        elif kind == "MISSION_CURRENT" and msg.seq != self._mission_seq:
            if self._mission_seq is not None:
                self.events.append(Event(LogLevel.INFO, f"mission: current item {msg.seq}"))
            self._mission_seq = msg.seq
        elif kind == "MISSION_ITEM_REACHED":
            self.events.append(Event(LogLevel.INFO, f"mission: reached item {msg.seq}"))
        elif kind in ("CAMERA_FEEDBACK", "CAMERA_TRIGGER"):
            self._trigger(kind, now_s)
        elif (
            kind == "COMMAND_ACK"
            and msg.command == M.MAV_CMD_IMAGE_START_CAPTURE
            and msg.result == M.MAV_RESULT_ACCEPTED
        ):
            self._trigger("IMAGE_START_CAPTURE accepted", now_s)

    def foreign(self, raw: bytes, now_s: float) -> None:
        """A frame from a system other than the vehicle, or one the recorder itself did not
        send: a ground station's heartbeat or camera command."""
        sysid, msgid = frame_ids(raw)
        if msgid not in _FOREIGN_IDS or sysid == self.target[0]:
            return
        for frame in self._parser.feed(raw):
            msg = frame.msg
            kind = msg.get_type()
            if kind == "HEARTBEAT" and msg.type == M.MAV_TYPE_GCS:
                if sysid not in self.other_gcs:
                    text = f"ground station sysid {sysid} heard on the link"
                    self.events.append(Event(LogLevel.INFO, text, "recorder"))
                self.other_gcs[sysid] = now_s
            elif kind in ("COMMAND_LONG", "COMMAND_INT") and msg.command in _CAMERA_COMMANDS:
                if self.addressed and msg.target_system not in (0, self.target[0]):
                    continue  # another vehicle's camera
                shot = msg.command == M.MAV_CMD_IMAGE_START_CAPTURE or _param5(msg) == 1
                if shot:
                    name = "IMAGE_START_CAPTURE"
                    if msg.command == M.MAV_CMD_DO_DIGICAM_CONTROL:
                        name = "DO_DIGICAM_CONTROL"
                    self._trigger(f"{name} from sysid {sysid}", now_s)

    # --- queries --------------------------------------------------------------------------

    def gcs_present(self, now_s: float) -> bool:
        return any(now_s - t < OTHER_GCS_S for t in self.other_gcs.values())

    @property
    def mode_unknown(self) -> bool:
        """Whether no heartbeat of the vehicle has reached this watch yet."""
        return self._mode is None

    def take_triggers(self) -> list[str]:
        out, self.triggers = self.triggers, []
        return out

    def take_events(self) -> list[Event]:
        out, self.events = self.events, []
        return out

    def flight_over(self, *, armed: bool, landed: bool) -> bool:
        """True once the vehicle has been seen airborne and is now landed and disarmed."""
        if armed and not landed:
            self.airborne_seen = True
        return self.airborne_seen and landed and not armed

    # --- internals ------------------------------------------------------------------------

    def _heartbeat(self, msg: Any) -> None:
        mode = (int(msg.custom_mode), bool(msg.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED))
        if mode == self._mode:
            return
        if self.autopilot is None:
            self.autopilot = for_vehicle(msg)
        name = self.autopilot.mode_name(mode[0])
        if self._mode is None:
            state = "armed" if mode[1] else "disarmed"
            self.events.append(Event(LogLevel.INFO, f"mode {name}, {state}"))
        else:
            if mode[0] != self._mode[0]:
                old = self.autopilot.mode_name(self._mode[0])
                self.events.append(Event(LogLevel.INFO, f"mode {old} → {name}"))
            if mode[1] != self._mode[1]:
                self.events.append(Event(LogLevel.INFO, "armed" if mode[1] else "disarmed"))
        self._mode = mode

    def _trigger(self, name: str, now_s: float) -> None:
        if self._last_trigger_s is not None and now_s - self._last_trigger_s < TRIGGER_MERGE_S:
            return
        self._last_trigger_s = now_s
        self.triggers.append(name)


def _param5(msg: Any) -> float:
    # COMMAND_INT carries param5 as the integer x
    return float(msg.param5 if msg.get_type() == "COMMAND_LONG" else msg.x)
