"""Feed a recording of ``uavtool record`` (no mission) into a `MissionLogger`: the route and
telemetry from ``/vehicle/telemetry``, each camera frame from ``/camera/frames`` with its
image, the events, and — after ``replay --vision-only -o`` — each photo's shapes and match
from ``/vision/results`` drawn over it, with the target picture."""

from __future__ import annotations

import json
from collections import defaultdict, deque
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.flight import scene_data
from uavtool.geo import GeoPoint
from uavtool.recording import CompressedImage, JsonDocument, LogEntry, RecordingReader
from uavtool.recording.annotations import DETECTIONS
from uavtool.recording.topics import FRAMES, IMAGE, TARGET, TELEMETRY, VEHICLE_EVENTS, VISION
from uavtool.view.errors import ViewError, showing
from uavtool.view.fleet import FleetLogger
from uavtool.view.logger import MissionLogger
from uavtool.world import SceneError, scene_from_dict

_LEVEL_NAMES = {1: "debug", 2: "info", 3: "warning", 4: "error", 5: "error"}


def is_recorded_flight(topics: set[str]) -> bool:
    return FRAMES in topics or TELEMETRY in topics


def log_recorded_flight(path: str | Path, reader: RecordingReader, logger: MissionLogger) -> None:
    """Log what ``reader`` (a recording of ``uavtool record``) holds through ``logger``."""
    metadata = dict(reader.metadata)
    present = set(reader.topics())
    _setup(path, metadata, logger)
    results: dict[int, list[dict[str, Any]]] = defaultdict(list)
    first = True
    for entry in reader.entries([t for t in (TARGET, VISION) if t in present]):
        with showing(path, entry):
            value = entry.value
            if isinstance(value, CompressedImage) and first:
                logger.target(value.data)
                first = False
            elif isinstance(value, JsonDocument):
                out = dict(value.payload)
                frame = int(out.get("frame_index", -1))
                if frame == -1:
                    logger.output(0, out)  # the target's shapes
                else:
                    results[frame].append(out)
    wanted = [t for t in (TELEMETRY, FRAMES, IMAGE, DETECTIONS, VEHICLE_EVENTS) if t in present]
    images: deque[bytes] = deque()
    for entry in reader.entries(wanted):
        with showing(path, entry):
            value, t_ns = entry.value, entry.log_time_ns
            if isinstance(value, CompressedImage):
                images.append(value.data)
            elif isinstance(value, JsonDocument) and entry.topic == TELEMETRY:
                logger.observation(0, value.payload, log_time_ns=t_ns)
            elif isinstance(value, JsonDocument) and entry.topic == DETECTIONS:
                logger.detections(value.payload, log_time_ns=t_ns)  # replay --vision's
            elif isinstance(value, JsonDocument) and entry.topic == FRAMES:
                record = dict(value.payload)
                logger.observation(
                    0, record, images.popleft() if images else None, log_time_ns=t_ns
                )
                for out in results.get(int(record.get("frame_index", -1)), []):
                    logger.output(0, out, log_time_ns=t_ns)
            elif isinstance(value, LogEntry):
                level = _LEVEL_NAMES.get(int(value.level), "info")
                logger.note(level, value.message, source=value.name or "vehicle", log_time_ns=t_ns)
    logger.flush()


def log_scene(
    path: str | Path, metadata: dict[str, dict[str, str]], logger: MissionLogger | FleetLogger
) -> None:
    """The scene in a recording's ``scene`` metadata, if any, to ``logger``."""
    try:
        data = scene_data(metadata, source=str(path))
        if data is not None:
            logger.scene(scene_from_dict(data, source=f"{path}: scene metadata"))
    except (InputError, SceneError) as exc:
        raise ViewError(f"{path}: scene metadata unreadable: {exc}") from None


def _setup(path: str | Path, metadata: dict[str, dict[str, str]], logger: MissionLogger) -> None:
    log_scene(path, metadata, logger)
    origin = metadata.get("record", {}).get("origin")
    if origin:
        try:
            lat, lon, alt = (float(v) for v in json.loads(origin))
        except (ValueError, TypeError):
            raise ViewError(f"{path}: metadata 'record': origin {origin!r} unreadable") from None
        logger.home(GeoPoint(lat, lon, alt))
    params = metadata.get("vision_only", {}).get("params")
    if params:
        try:
            logger.params(json.loads(params))
        except ValueError:
            raise ViewError(f"{path}: metadata 'vision_only': params are not JSON") from None
