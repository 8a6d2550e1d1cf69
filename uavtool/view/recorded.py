"""Feed a recording of ``uavtool record`` (no mission) into a `MissionLogger`: the route and
telemetry from ``/vehicle/telemetry``, each camera frame from ``/camera/frames`` with its
image, the events, and — after ``replay --vision-only -o`` — each photo's shapes and match
from ``/vision/results`` drawn over it, with the target picture. A fleet's (``record
--vehicles N``) goes into a `FleetLogger`: each vehicle's topics under ``/uavK`` through its
own logger, as one vehicle's go through the one."""

from __future__ import annotations

import json
from collections import defaultdict, deque
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.flight import mission_of, scene_data
from uavtool.geo import GeoPoint
from uavtool.recording import CompressedImage, JsonDocument, LogEntry, RecordingReader
from uavtool.recording.annotations import DETECTIONS
from uavtool.recording.fleet import vehicle_prefix
from uavtool.recording.topics import FRAMES, IMAGE, TARGET, TELEMETRY, VEHICLE_EVENTS, VISION
from uavtool.view.errors import ViewError, showing
from uavtool.view.fleet import FleetLogger
from uavtool.view.logger import MissionLogger
from uavtool.world import SceneError, scene_from_dict

_LEVEL_NAMES = {1: "debug", 2: "info", 3: "warning", 4: "error", 5: "error"}


def is_recorded_flight(topics: set[str]) -> bool:
    return FRAMES in topics or TELEMETRY in topics


def log_recorded_flight(path: str | Path, reader: RecordingReader, logger: MissionLogger) -> None:
    """Log what ``reader`` (a recording of ``uavtool record``, one vehicle) holds through
    ``logger``."""
    metadata = dict(reader.metadata)
    log_scene(path, metadata, logger)
    origin = metadata.get("record", {}).get("origin")
    if origin:
        logger.home(_geo(path, origin, "origin"))
    params = _params(path, metadata)
    if params is not None:
        logger.params(params)
    log_recorded_vehicle(path, reader, logger)
    logger.flush()


def log_recorded_fleet(path: str | Path, reader: RecordingReader, fleet: FleetLogger) -> None:
    """Log what ``reader`` (a fleet's recording of ``uavtool record --vehicles N``) holds
    through ``fleet`` (made for its vehicles): the scene and the target once, each vehicle's
    topics under ``/uavK`` through its own logger, its home from the ``record`` metadata."""
    metadata = dict(reader.metadata)
    log_scene(path, metadata, fleet)
    params = _params(path, metadata)
    if params is not None:
        fleet.params(params)
    if TARGET in set(reader.topics()):
        for entry in reader.entries([TARGET]):
            if isinstance(entry.value, CompressedImage):
                fleet.target(entry.value.data)
            break
    origins = _origins(path, metadata.get("record", {}))
    for k, logger in fleet.vehicles.items():
        if k in origins:
            logger.home(origins[k])
        log_recorded_vehicle(path, reader, logger, prefix=vehicle_prefix(k))
    fleet.flush()


def log_recorded_vehicle(
    path: str | Path, reader: RecordingReader, logger: MissionLogger, *, prefix: str = ""
) -> None:
    """Log one vehicle's topics of a recording of ``uavtool record`` (under ``prefix``, a
    fleet's ``/uavK``) through ``logger``: its target picture and ``replay --vision-only``
    results if any, then its telemetry, frames, detections and events in order."""
    present = set(reader.topics())
    mine = {prefix + t: t for t in (TARGET, VISION) if prefix + t in present}
    results: dict[int, list[dict[str, Any]]] = defaultdict(list)
    first = True
    for entry in reader.entries(list(mine)):
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
    topics = (TELEMETRY, FRAMES, IMAGE, DETECTIONS, VEHICLE_EVENTS)
    mine = {prefix + t: t for t in topics if prefix + t in present}
    images: deque[bytes] = deque()
    for entry in reader.entries(list(mine)):
        with showing(path, entry):
            value, t_ns, topic = entry.value, entry.log_time_ns, mine[entry.topic]
            if isinstance(value, CompressedImage):
                images.append(value.data)
            elif isinstance(value, JsonDocument) and topic == TELEMETRY:
                logger.observation(0, value.payload, log_time_ns=t_ns)
            elif isinstance(value, JsonDocument) and topic == DETECTIONS:
                logger.detections(value.payload, log_time_ns=t_ns)  # replay --vision's
            elif isinstance(value, JsonDocument) and topic == FRAMES:
                record = dict(value.payload)
                logger.observation(
                    0, record, images.popleft() if images else None, log_time_ns=t_ns
                )
                for out in results.get(int(record.get("frame_index", -1)), []):
                    logger.output(0, out, log_time_ns=t_ns)
            elif isinstance(value, LogEntry):
                level = _LEVEL_NAMES.get(int(value.level), "info")
                logger.note(level, value.message, source=value.name or "vehicle", log_time_ns=t_ns)


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


def log_flight_setup(
    path: str | Path,
    reader: RecordingReader,
    metadata: dict[str, dict[str, str]],
    logger: MissionLogger | FleetLogger,
) -> set[str]:
    """What a flight's view starts with, one vehicle's or a fleet's: the scene, the
    mission's parameters and the target picture; returns the recording's topics."""
    log_scene(path, metadata, logger)
    try:
        _, params = mission_of(metadata, source=str(path))
    except InputError as exc:
        raise ViewError(str(exc)) from None
    logger.params(params)
    topics = set(reader.topics())
    if TARGET in topics:
        for entry in reader.entries([TARGET]):
            if isinstance(entry.value, CompressedImage):
                logger.target(entry.value.data)
            break
    return topics


def _geo(path: str | Path, text: str, name: str) -> GeoPoint:
    """A ``record`` metadata's ``[lat, lon, alt]`` (``name``: which, for the error)."""
    try:
        lat, lon, alt = (float(v) for v in json.loads(text))
    except (ValueError, TypeError):
        raise ViewError(f"{path}: metadata 'record': {name} {text!r} unreadable") from None
    return GeoPoint(lat, lon, alt)


def _origins(path: str | Path, record: dict[str, str]) -> dict[int, GeoPoint]:
    """A fleet's origins (its vehicles' homes) by system id, from ``record``'s
    ``vehicle_sysids`` and ``origins``; none if it names none."""
    sysids, origins = record.get("vehicle_sysids"), record.get("origins")
    if not sysids or not origins:
        return {}
    try:
        ks = [int(k) for k in json.loads(sysids)]
        points = [GeoPoint(*(float(c) for c in o)) for o in json.loads(origins)]
    except (ValueError, TypeError):
        raise ViewError(
            f"{path}: metadata 'record': vehicle_sysids or origins unreadable"
        ) from None
    if len(ks) != len(points):
        raise ViewError(f"{path}: metadata 'record': {len(points)} origins for {len(ks)} vehicles")
    return dict(zip(ks, points, strict=True))


def _params(path: str | Path, metadata: dict[str, dict[str, str]]) -> Any:
    """The parameters ``replay --vision-only`` ran with, if any."""
    params = metadata.get("vision_only", {}).get("params")
    if not params:
        return None
    try:
        return json.loads(params)
    except ValueError:
        raise ViewError(f"{path}: metadata 'vision_only': params are not JSON") from None
