"""Feed a recording into a `MissionLogger`, in the order it was written.

The mission's own streams (``/mission/observations``, ``/mission/outputs``) drive the
logger exactly as the live runner does; the frames come from ``/camera/image`` (the k-th
image is frame k, written just before its ``Photo``), vehicle text from STATUSTEXT, the
home from HOME_POSITION, and the ground truth from the ``scene`` metadata. A fleet's
recording goes through `~uavtool.view.fleet_source.log_fleet_recording` instead, each
vehicle's topics through `log_entry` as one vehicle's (a recorded fleet's through
`~uavtool.view.recorded.log_recorded_vehicle`).
"""

from __future__ import annotations

from collections import deque
from pathlib import Path

from uavtool.geo import GeoPoint
from uavtool.recording import CompressedImage, Entry, JsonDocument, LogEntry, RecordingReader
from uavtool.recording.annotations import DETECTIONS
from uavtool.recording.fleet import split_topic
from uavtool.recording.topics import EVENTS, IMAGE, OBSERVATIONS, OUTPUTS, PICTURES
from uavtool.view.errors import ViewError, showing
from uavtool.view.logger import MissionLogger
from uavtool.view.recorded import is_recorded_flight, log_flight_setup, log_recorded_flight

STATUSTEXT = "/mavlink/in/STATUSTEXT"
HOME_POSITION = "/mavlink/in/HOME_POSITION"
_LEVEL_NAMES = {1: "debug", 2: "info", 3: "warning", 4: "error", 5: "error"}


def log_recording(path: str | Path, logger: MissionLogger) -> None:
    """Log everything ``path`` holds through ``logger``: a mission's recording, or one
    vehicle's of ``uavtool record``. Raises `NotMcapError` if it is not a recording,
    `ViewError` if it holds neither, or is a fleet's (``fly`` or ``record --vehicles N``:
    `~uavtool.view.fleet_source.log_fleet_recording` shows those)."""
    with RecordingReader(path) as reader:
        present = set(reader.topics())
        if OBSERVATIONS not in present and is_recorded_flight(present):
            log_recorded_flight(path, reader, logger)  # from `uavtool record`: no mission
            return
        if OBSERVATIONS not in present and fleet_sysids(present):
            raise ViewError(
                f"{path}: a fleet's recording (its vehicles' topics under /uavN): one "
                "MissionLogger shows one vehicle; log_fleet_recording shows every vehicle "
                "through a FleetLogger, as view does"
            )
        if OBSERVATIONS not in present:
            raise ViewError(f"{path}: no {OBSERVATIONS} topic: not a mission recording")
        reader.require_metadata(("scene", "mission"))  # else the view would lack them quietly
        metadata = dict(reader.metadata)
        _setup(path, reader, metadata, logger)
        wanted = [t for t in (*MISSION_TOPICS, STATUSTEXT) if t in present]
        images: deque[bytes] = deque()
        for entry in reader.entries(wanted):
            with showing(path, entry):
                log_entry(entry.topic, entry, images, logger)
    logger.flush()


_MAX_VEHICLES = 64  # as many as a recording may say flew (`uavtool sitl --vehicles`)


def fleet_sysids(topics: set[str]) -> list[int]:
    """The system ids of the vehicles whose mission (or, from ``record --vehicles N``,
    telemetry or frames) ``topics`` holds under ``/uavK``, in order; none for a one-vehicle
    recording."""
    found = {
        k
        for k, sub in map(split_topic, topics)
        if k is not None and (sub == OBSERVATIONS or is_recorded_flight({sub}))
    }
    return sorted(k for k in found if k <= _MAX_VEHICLES)


MISSION_TOPICS = (OBSERVATIONS, OUTPUTS, IMAGE, PICTURES, DETECTIONS, EVENTS)
"""The topics of one vehicle's mission that `log_entry` shows (STATUSTEXT besides)."""


def log_entry(topic: str, entry: Entry, images: deque[bytes], logger: MissionLogger) -> None:
    """Log one message of ``topic`` (as a one-vehicle recording names it) through
    ``logger``; ``images`` holds the camera frames not yet paired with their ``Photo``."""
    value, t_ns = entry.value, entry.log_time_ns
    if topic == IMAGE and isinstance(value, CompressedImage):
        images.append(value.data)
    elif topic == PICTURES and isinstance(value, CompressedImage):
        logger.picture(value.frame_id, value.data, log_time_ns=t_ns)
    elif isinstance(value, JsonDocument) and topic == OBSERVATIONS:
        obs = value.payload
        png = images.popleft() if obs.get("type") == "Photo" and images else None
        logger.observation(int(obs.get("step", 0)), obs, png, log_time_ns=t_ns)
    elif isinstance(value, JsonDocument) and topic == OUTPUTS:
        out = value.payload
        logger.output(int(out.get("n", 0)), out, log_time_ns=t_ns)
    elif isinstance(value, JsonDocument) and topic == DETECTIONS:
        logger.detections(value.payload, log_time_ns=t_ns)
    elif isinstance(value, JsonDocument) and topic == STATUSTEXT:
        msg = value.payload
        logger.statustext(int(msg.get("severity", 6)), str(msg.get("text", "")), log_time_ns=t_ns)
    elif isinstance(value, LogEntry) and value.name == "runner":
        # The mission's own events come from /mission/outputs and the vehicle's
        # from STATUSTEXT; this topic repeats both, so only the runner's are new.
        level = _LEVEL_NAMES.get(int(value.level), "info")
        logger.note(level, value.message, source="runner", log_time_ns=t_ns)


def _setup(
    path: str | Path,
    reader: RecordingReader,
    metadata: dict[str, dict[str, str]],
    logger: MissionLogger,
) -> None:
    topics = log_flight_setup(path, reader, metadata, logger)
    if HOME_POSITION in topics:
        for entry in reader.entries([HOME_POSITION]):
            if isinstance(entry.value, JsonDocument):
                msg = entry.value.payload
                with showing(path, entry):
                    home = GeoPoint(
                        msg["latitude"] / 1e7, msg["longitude"] / 1e7, msg["altitude"] / 1e3
                    )
                    logger.home(home)
            break
