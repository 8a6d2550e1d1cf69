"""Where a passive recording's messages go: the same `RecordingWriter`, topics and Foxglove
values as a mission's, with the vehicle's telemetry and the camera's frames in place of the
mission's observations (docs/record.md)."""

from __future__ import annotations

from typing import Any

from uavtool.geo import GeoPoint
from uavtool.mission import Telemetry
from uavtool.mission.codec import encode, encode_observation
from uavtool.recorder.frames import Frame
from uavtool.recorder.watch import Event
from uavtool.recording import Direction, LogEntry
from uavtool.recording.protocol import MessageWriter
from uavtool.recording.topics import (
    FRAMES,
    TELEMETRY,
    VEHICLE_EVENTS,
)
from uavtool.runner.record import ClockNs, write_camera_frame

TELEMETRY_SCHEMA = {
    "title": "uavtool.Telemetry",
    "description": "The vehicle's state from GLOBAL_POSITION_INT, HEARTBEAT, "
    "EXTENDED_SYS_STATE and the gimbal status, in ENU metres around the recording's origin.",
    "type": "object",
    "properties": {
        "time_boot_ms": {"type": "integer"},
        "pos_enu_m": {"type": "array", "items": {"type": "number"}},
        "heading_deg": {"type": "number"},
        "mode": {"type": "string"},
        "armed": {"type": "boolean"},
        "landed": {"type": "boolean"},
    },
    "required": ["time_boot_ms", "pos_enu_m"],
}
FRAME_SCHEMA = {
    "title": "uavtool.Frame",
    "description": "A camera frame's capture (vehicle time) and pose; its pixels are the "
    "frame_index-th message on /camera/image.",
    "type": "object",
    "properties": {
        "frame_index": {"type": "integer"},
        "tag": {"type": "string"},
        "photo": {"type": "integer"},
        "trigger": {"type": "string"},
        "time_boot_ms": {"type": "integer"},
        "pose_time_boot_ms": {"type": "integer"},
        "pose_dt_ms": {"type": "integer"},
    },
    "required": ["frame_index", "time_boot_ms"],
}


class LinkRecorder:
    """Writes every MAVLink frame crossing a link into ``writer``'s shared ``/mavlink``
    channels, stamped by ``clock_ns``, and counts them (``counts["in"]``, ``["out"]``)."""

    def __init__(self, writer: MessageWriter, *, clock_ns: ClockNs) -> None:
        self.writer = writer
        self.clock_ns = clock_ns
        self.counts = {"in": 0, "out": 0}

    def mavlink(self, direction: str, frame: bytes, decoded: Any = None) -> None:
        """The link's tap: every whole frame, as it crossed the link (and the message the
        link decoded from it, if any)."""
        self.counts[direction] += 1
        self.writer.write_mavlink(
            frame,
            direction=Direction.IN if direction == "in" else Direction.OUT,
            log_time_ns=self.clock_ns(),
            decoded=decoded,
        )


class PassiveRecorder(LinkRecorder):
    """Writes a flight it does not command into ``writer``, stamped by ``clock_ns``;
    ``origin`` is the local frame's origin (the vehicle's home) for WGS-84 fixes. One vehicle
    of a fleet writes through a `~uavtool.recording.fleet.VehicleWriter`: its topics under
    ``/uavK``, its MAVLink frames (when it taps them) on the shared channels."""

    def __init__(self, writer: MessageWriter, *, clock_ns: ClockNs, origin: GeoPoint) -> None:
        super().__init__(writer, clock_ns=clock_ns)
        self.origin = origin
        self.counts = {"in": 0, "out": 0, "telemetry": 0, "frames": 0, "photos": 0, "events": 0}
        self.max_pose_dt_ms = 0
        writer.add_json_topic(TELEMETRY, schema_name="uavtool.Telemetry", schema=TELEMETRY_SCHEMA)
        writer.add_json_topic(FRAMES, schema_name="uavtool.Frame", schema=FRAME_SCHEMA)

    def telemetry(self, t: Telemetry) -> None:
        now = self.clock_ns()
        self.counts["telemetry"] += 1
        self.writer.write_json(TELEMETRY, encode_observation(t), log_time_ns=now)
        self.writer.write_vehicle(t.pos_enu_m, t.heading_deg, self.origin, log_time_ns=now)

    def frame(self, f: Frame) -> None:
        now = self.clock_ns()
        self.counts["frames"] += 1
        self.counts["photos"] += f.photo >= 0
        self.max_pose_dt_ms = max(self.max_pose_dt_ms, abs(f.pose_dt_ms))
        write_camera_frame(self.writer, f.png, f.intrinsics, f.pose, now)
        record = {
            "type": "Photo",
            "action_id": -1,
            "frame_index": f.index,
            "tag": f.tag,
            "time_boot_ms": f.time_boot_ms,
            "pose": encode(f.pose),
            "intrinsics": encode(f.intrinsics),
            "photo": f.photo,
            "trigger": f.trigger,
            "pose_time_boot_ms": f.pose_time_boot_ms,
            "pose_dt_ms": f.pose_dt_ms,
        }
        self.writer.write_json(FRAMES, record, log_time_ns=now)

    def event(self, e: Event) -> None:
        self.counts["events"] += 1
        entry = LogEntry(e.level, e.text, name=e.source)
        self.writer.write(VEHICLE_EVENTS, entry, log_time_ns=self.clock_ns())
