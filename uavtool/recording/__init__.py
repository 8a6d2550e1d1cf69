"""Recordings: one MCAP file per mission — write, read (even when cut), inspect, recover,
and bridge to MAVProxy's ``.tlog``. The topic list is in docs/recording-format.md.

The names below are imported on first use: a writer process (`uavtool.recording.process`)
and the commands that only read need a part of them, and the rest costs numpy, OpenCV's
and Foxglove's modules at start-up.
"""

import importlib
from typing import TYPE_CHECKING, Any

from uavtool.recording.errors import (
    CorruptRecordingError,
    NotMcapError,
    RecordingError,
    TlogError,
    TopicNotFoundError,
    UnknownSchemaError,
)

if TYPE_CHECKING:
    from uavtool.recording.info import RecordingInfo, summarize
    from uavtool.recording.process import ProcessWriter
    from uavtool.recording.reader import Message, RecordingReader
    from uavtool.recording.recovery import recover
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
        RgbImage,
        SceneEntity,
        SceneMarkers,
        TriangleMesh,
    )
    from uavtool.recording.writer import RecordingWriter

_VALUES = (
    "CameraCalibration CompressedImage Direction Entry FrameTransform JsonDocument LocationFix "
    "LogEntry LogLevel MavlinkFrame Model3D Pose PosesInFrame RgbImage SceneEntity SceneMarkers "
    "TriangleMesh"
)
_MODULE_OF = {
    **dict.fromkeys(_VALUES.split(), "values"),
    "RecordingInfo": "info",
    "summarize": "info",
    "Message": "reader",
    "RecordingReader": "reader",
    "recover": "recovery",  # not the module's own name: importing it would shadow this
    "export_tlog": "tlog",
    "import_tlog": "tlog",
    "RecordingWriter": "writer",
    "ProcessWriter": "process",
}


def __getattr__(name: str) -> Any:
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


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
    "ProcessWriter",
    "RecordingError",
    "RecordingInfo",
    "RecordingReader",
    "RecordingWriter",
    "RgbImage",
    "SceneEntity",
    "SceneMarkers",
    "TlogError",
    "TopicNotFoundError",
    "TriangleMesh",
    "UnknownSchemaError",
    "export_tlog",
    "import_tlog",
    "recover",
    "summarize",
]
