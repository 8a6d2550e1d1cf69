"""Recordings: one MCAP file per mission — write, read (even when cut), inspect, recover,
and bridge to MAVProxy's ``.tlog``. The topic list is in docs/recording-format.md."""

from uavtool.recording.errors import (
    CorruptRecordingError,
    NotMcapError,
    RecordingError,
    TlogError,
    TopicNotFoundError,
    UnknownSchemaError,
)
from uavtool.recording.info import RecordingInfo, summarize
from uavtool.recording.reader import Message, RecordingReader
from uavtool.recording.recover import recover
from uavtool.recording.tlog import export_tlog, import_tlog
from uavtool.recording.values import (
    CameraCalibration,
    CompressedImage,
    Direction,
    Entry,
    FrameTransform,
    JsonDocument,
    LocationFix,
    LogEntry,
    LogLevel,
    MavlinkFrame,
    Model3D,
    Pose,
    PosesInFrame,
    SceneEntity,
    SceneMarkers,
)
from uavtool.recording.writer import RecordingWriter

__all__ = [
    "CameraCalibration",
    "CompressedImage",
    "CorruptRecordingError",
    "Direction",
    "Entry",
    "FrameTransform",
    "JsonDocument",
    "LocationFix",
    "LogEntry",
    "LogLevel",
    "MavlinkFrame",
    "Message",
    "Model3D",
    "NotMcapError",
    "Pose",
    "PosesInFrame",
    "RecordingError",
    "RecordingInfo",
    "RecordingReader",
    "RecordingWriter",
    "SceneEntity",
    "SceneMarkers",
    "TlogError",
    "TopicNotFoundError",
    "UnknownSchemaError",
    "export_tlog",
    "import_tlog",
    "recover",
    "summarize",
]
