"""Deterministic sample recordings for the recording tests: real MAVLink frames built with
pymavlink's ardupilotmega dialect, and one message of every other kind."""

from __future__ import annotations

import math
from pathlib import Path

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from uavtool.camera import CameraPose, Intrinsics
from uavtool.recording import (
    CameraCalibration,
    CompressedImage,
    Direction,
    FrameTransform,
    LocationFix,
    LogEntry,
    LogLevel,
    Model3D,
    Pose,
    PosesInFrame,
    RecordingWriter,
)

T0_NS = 1_700_000_000_000_000_000
OBS_SCHEMA = {
    "type": "object",
    "properties": {"step": {"type": "integer"}, "alt_m": {"type": "number"}},
}


def mavlink_frames(n: int) -> list[tuple[Direction, bytes]]:
    """``n`` frames of a plausible link: vehicle telemetry in, GCS heartbeats/commands out."""
    vehicle = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    out: list[tuple[Direction, bytes]] = []
    for i in range(n):
        kind = i % 5
        if kind == 0:
            msg = mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3)
            out.append((Direction.OUT, bytes(msg.pack(gcs))))
        elif kind == 1:
            msg = mavlink.MAVLink_attitude_message(
                i * 10, 0.01 * i, -0.02, math.pi / 3, 0.0, 0.0, 0.1
            )
            out.append((Direction.IN, bytes(msg.pack(vehicle))))
        elif kind == 2:
            msg = mavlink.MAVLink_global_position_int_message(
                i * 10, 473977420 + i, 85455940, 500000, 45000 + i, 10, -5, 0, 9000
            )
            out.append((Direction.IN, bytes(msg.pack(vehicle))))
        elif kind == 3:
            nan = float("nan")
            msg = mavlink.MAVLink_command_long_message(
                1, 1, 115, 0, 90.0, 10.0, 1.0, 0.0, nan, nan, nan
            )
            out.append((Direction.OUT, bytes(msg.pack(gcs))))
        else:
            msg = mavlink.MAVLink_statustext_message(6, f"step {i}".encode(), 0, 0)
            out.append((Direction.IN, bytes(msg.pack(vehicle))))
    return out


def other_values() -> list[tuple[str, object]]:
    """One value of every non-MAVLink kind, with the topic it goes to."""
    intrinsics = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
    pose = CameraPose((10.0, -4.5, 45.0), heading_deg=30.0, pitch_deg=-90.0)
    return [
        ("/camera/image", CompressedImage(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 8)),
        ("/camera/calibration", CameraCalibration.from_intrinsics(intrinsics)),
        ("/camera/pose", FrameTransform.from_camera_pose(pose)),
        ("/vehicle/fix", LocationFix(47.397742, 8.545594, 488.25)),
        ("/vehicle/pose", PosesInFrame((Pose.from_enu_heading((1.0, 2.0, 45.0), 90.0),))),
        (
            "/mission/events",
            LogEntry(LogLevel.WARNING, "target matched: red", file="mission.py", line=7),
        ),
        ("/mission/model", Model3D(b"glTF" + bytes(100), pose=Pose((5.0, 6.0, 0.0)))),
    ]


def write_sample(
    path: Path,
    *,
    seconds: float = 3.0,
    rate_hz: int = 100,
    chunk_interval_ns: int = 1_000_000_000,
    chunk_bytes: int = 1 << 20,
    fsync: bool = False,
) -> int:
    """Write a deterministic recording; returns the number of messages written."""
    frames = mavlink_frames(int(seconds * rate_hz))
    step_ns = 1_000_000_000 // rate_hz
    metadata = {"mission": {"target": "red", "alt_m": "45"}, "seeds": {"world": "7"}}
    with RecordingWriter(
        path,
        metadata=metadata,
        chunk_interval_ns=chunk_interval_ns,
        chunk_bytes=chunk_bytes,
        fsync=fsync,
    ) as writer:
        writer.add_json_topic(
            "/mission/observations", schema_name="test.Observation", schema=OBS_SCHEMA
        )
        for i, (direction, frame) in enumerate(frames):
            t = T0_NS + i * step_ns
            writer.write_mavlink(
                frame, direction=direction, log_time_ns=t, publish_time_ns=i * step_ns + 1
            )
            if i % rate_hz == 0:
                writer.write_json(
                    "/mission/observations", {"step": i, "alt_m": 45.0}, log_time_ns=t
                )
                for topic, value in other_values():
                    writer.write(topic, value, log_time_ns=t)  # type: ignore[arg-type]
        writer.add_metadata("outcome", {"result": "matched", "building": "red"})
        return writer.message_count
