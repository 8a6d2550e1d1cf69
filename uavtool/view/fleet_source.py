"""Feed a fleet's recording (``uavtool fly --vehicles N``) into a `FleetLogger`.

Vehicle K's topics (``/uavK/mission/observations``, ``/uavK/camera/image`` …) go to its own
`MissionLogger` as a one-vehicle recording's go to the one logger; the shared MAVLink channels
(STATUSTEXT, HOME_POSITION) to the vehicle whose system id sent them; the target picture and
the fleet's outcome (``outcome`` metadata) to the fleet. Each vehicle's home in the fleet's
frame comes from the ``crew`` metadata. A fleet recorded by ``uavtool record --vehicles N``
(no mission) goes through `~uavtool.view.recorded.log_recorded_fleet`, in the same layout.
"""

from __future__ import annotations

import json
import math
from collections import deque
from pathlib import Path
from typing import Any

from uavtool.geo import GeoPoint
from uavtool.recording import Entry, JsonDocument, RecordingReader
from uavtool.recording.fleet import CREW_METADATA, vehicle_prefix
from uavtool.recording.topics import OBSERVATIONS
from uavtool.view.errors import ViewError, showing
from uavtool.view.fleet import FleetLogger
from uavtool.view.paths import FleetVehicle
from uavtool.view.recorded import log_flight_setup, log_recorded_fleet
from uavtool.view.source import HOME_POSITION, MISSION_TOPICS, STATUSTEXT, fleet_sysids, log_entry


def fleet_of(path: str | Path) -> tuple[FleetVehicle, ...]:
    """The vehicles of the fleet ``path`` recorded, each with its home in the fleet's frame;
    none for a one-vehicle recording. Raises `NotMcapError` for a file that is not a
    recording, `ViewError` for a fleet whose homes are missing or malformed."""
    with RecordingReader(path) as reader:
        present = set(reader.topics())
        sysids = [] if OBSERVATIONS in present else fleet_sysids(present)
        if not sysids:
            return ()
        crew = dict(reader.metadata).get(CREW_METADATA, {})
    homes = _homes(path, crew.get("homes_en_m"))
    if len(homes) != len(sysids):
        raise ViewError(
            f"{path}: metadata {CREW_METADATA!r}: {len(homes)} homes for the "
            f"{len(sysids)} vehicles {', '.join(vehicle_prefix(k) for k in sysids)}"
        )
    # The homes are in system-id order, as the fleet's runner wrote them.
    return tuple(FleetVehicle(k, home) for k, home in zip(sysids, homes, strict=True))


def log_fleet_recording(path: str | Path, fleet: FleetLogger) -> None:
    """Log everything the fleet's recording ``path`` holds through ``fleet`` (made for the
    vehicles `fleet_of` found in it): a fleet's mission, or a fleet ``uavtool record``
    recorded. Raises `ViewError` if it holds neither."""
    with RecordingReader(path) as reader:
        present = set(reader.topics())
        missions = any(vehicle_prefix(k) + OBSERVATIONS in present for k in fleet.vehicles)
        if not missions and fleet_sysids(present):  # from `record --vehicles N`: no mission
            log_recorded_fleet(path, reader, fleet)
            return
        reader.require_metadata(("scene", "mission"))  # else the view would lack them quietly
        metadata = dict(reader.metadata)
        _setup(path, reader, metadata, fleet)
        mine = {
            vehicle_prefix(k) + topic: (k, topic)
            for k in fleet.vehicles
            for topic in MISSION_TOPICS
            if vehicle_prefix(k) + topic in present
        }
        wanted = [*mine, *([STATUSTEXT] if STATUSTEXT in present else [])]
        images: dict[int, deque[bytes]] = {k: deque() for k in fleet.vehicles}
        last_ns: int | None = None
        for entry in reader.entries(wanted):
            with showing(path, entry):
                k, topic = mine.get(entry.topic) or (_sender(entry), entry.topic)
                if k is not None and k in fleet.vehicles:  # not a ground station's
                    log_entry(topic, entry, images[k], fleet.vehicles[k])
                last_ns = entry.log_time_ns
    fleet.flush()
    _outcome(metadata.get("outcome", {}), fleet, last_ns)


def _sender(entry: Entry) -> int | None:
    """The system id that sent a shared MAVLink message (its header's)."""
    value = entry.value
    if not isinstance(value, JsonDocument):
        return None
    header = value.payload.get("header")
    sysid = header.get("sysid") if isinstance(header, dict) else None
    return sysid if isinstance(sysid, int) else None


def _setup(
    path: str | Path,
    reader: RecordingReader,
    metadata: dict[str, dict[str, str]],
    fleet: FleetLogger,
) -> None:
    topics = log_flight_setup(path, reader, metadata, fleet)
    if HOME_POSITION in topics:
        homeless = set(fleet.vehicles)
        for entry in reader.entries([HOME_POSITION]):
            k = _sender(entry)
            if k not in homeless or not isinstance(entry.value, JsonDocument):
                continue
            msg = entry.value.payload
            with showing(path, entry):
                home = GeoPoint(
                    msg["latitude"] / 1e7, msg["longitude"] / 1e7, msg["altitude"] / 1e3
                )
            fleet.vehicles[k].home(home)
            homeless.discard(k)
            if not homeless:
                break


def _outcome(record: dict[str, str], fleet: FleetLogger, log_time_ns: int | None) -> None:
    """The fleet's outcome (``outcome`` metadata) as the fleet's last line."""
    status = record.get("status")
    if not status:
        return  # a cut file: the flight's end was not written
    text = f"fleet outcome: {status}: {record.get('reason', '')}"
    closest = record.get("closest_approach_m")
    if closest:
        text += f"; closest approach {closest} m (kept: {record.get('separation_m', '?')} m)"
    level = {"completed": "info", "partial": "warning", "no-match": "warning"}.get(status, "error")
    fleet.note(level, text, log_time_ns=log_time_ns)


def _homes(path: str | Path, text: str | None) -> list[tuple[float, float]]:
    """``crew.homes_en_m``: ``[[east, north], …]`` in metres."""
    where = f"{path}: metadata {CREW_METADATA!r}: homes_en_m"
    if text is None:
        raise ViewError(f"{where} is missing: where each vehicle's home is")
    try:
        value: Any = json.loads(text) if len(text) < 100_000 else None
        homes = [(float(e), float(n)) for e, n in value]
    except (ValueError, TypeError, RecursionError):
        raise ViewError(f"{where} is malformed: {text[:60]!r}") from None
    if not all(math.isfinite(c) for home in homes for c in home):
        raise ViewError(f"{where} is malformed: {text[:60]!r}")
    return homes
