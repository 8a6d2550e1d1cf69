"""A recorded flight as replay needs it: the mission and its parameters, the target picture
(if the mission has one), every observation in the order the mission consumed it (photos with
their pixels), and every recorded output. Nothing else is read: not the scene, not the
vehicle, not the network."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.flight import MAX_FLEET, mission_of
from uavtool.images import png_decode
from uavtool.mission import FlightMission, Observation
from uavtool.mission.codec import decode_observation, without_nulls
from uavtool.mission.observations import U8Array
from uavtool.plugins import MissionRef, for_recording, mission_params
from uavtool.recording import CompressedImage, JsonDocument, RecordingReader
from uavtool.recording.fleet import CREW_METADATA, FLEET_METADATA, vehicle_prefix
from uavtool.recording.topics import IMAGE, OBSERVATIONS, OUTPUTS, TARGET

_NEEDED_METADATA = ("mission", "uavtool")  # the parameters, the version that recorded them


class ReplayInputError(InputError):
    """The recording cannot be replayed (not a mission recording, frames missing …)."""


@dataclass(frozen=True, slots=True)
class RecordedOutput:
    """One recorded output: its number ``n``, the ``step`` (observation) that produced it, and
    its JSON form without those two keys."""

    n: int
    step: int
    data: dict[str, Any]


@dataclass(frozen=True, slots=True)
class RecordedFlight:
    path: Path
    mission: type[FlightMission]
    """The class of the mission that flew (a registered one, or the one ``--mission`` named)."""
    mission_ref: MissionRef
    params: Any
    """The recorded parameters, an instance of ``mission.params_type``."""
    params_json: dict[str, Any]
    target_rgb: U8Array | None
    observations: tuple[Observation, ...]
    outputs: tuple[RecordedOutput, ...]
    truncated: bool
    tool_version: str

    @property
    def has_outcome(self) -> bool:
        """Whether the recorded outputs end the mission with an Outcome."""
        return any(o.data.get("type") == "Outcome" for o in self.outputs)


def load_flight(path: str | Path, *, mission: str | None = None) -> RecordedFlight:
    """Read a recording made by ``uavtool fly``; raises a one-line InputError naming the file
    and what is missing or wrong. ``mission`` (``--mission``) names the mission's class when
    the recording's is not registered here."""
    path = Path(path)
    with RecordingReader(path) as reader:
        reader.require_metadata(_NEEDED_METADATA)
        meta = dict(reader.metadata)
        if "mission" not in meta or OBSERVATIONS not in reader.topics():
            if FLEET_METADATA in meta:
                raise ReplayInputError(
                    f"{path}: a fleet's recording (its vehicles' topics under /uavN): "
                    "replay it with `uavtool replay --check` or `--refly`"
                )
            raise ReplayInputError(
                f"{path}: not a mission recording (no mission parameters or "
                f"{OBSERVATIONS}); record one with `uavtool fly`"
            )
        cls, ref, params, params_json, tool_version = _mission(meta, path, mission)
        target = _target(reader, path)
        raw_obs, images, outputs = _read_vehicle(reader, path, "")
        truncated = not reader.health.whole
    if target is None and cls.needs_target:
        raise ReplayInputError(f"{path}: the target picture ({TARGET}) is missing")
    for i, data in enumerate(raw_obs, start=1):
        if data.get("step") != i:
            raise ReplayInputError(
                f"{path}: observation {i} is missing (next recorded is step {data.get('step')})"
            )
    return RecordedFlight(
        path,
        cls,
        ref,
        params,
        params_json,
        target,
        tuple(_decode(path, "", raw_obs, images)),
        tuple(outputs),
        truncated,
        tool_version,
    )


@dataclass(frozen=True, slots=True)
class RecordedVehicle:
    """One vehicle of a fleet's recording: its system id, its observations with the fleet's
    step numbers (one order for every member), and its outputs."""

    sysid: int
    steps: tuple[int, ...]
    observations: tuple[Observation, ...]
    outputs: tuple[RecordedOutput, ...]


@dataclass(frozen=True, slots=True)
class RecordedFleet:
    path: Path
    mission: type[FlightMission]
    mission_ref: MissionRef
    params: Any
    params_json: dict[str, Any]
    target_rgb: U8Array | None
    homes_en_m: tuple[tuple[float, float], ...]
    vehicles: tuple[RecordedVehicle, ...]
    truncated: bool
    tool_version: str


def is_fleet(path: str | Path) -> bool:
    """Whether ``path`` holds a fleet's flight (several vehicles' topics)."""
    with RecordingReader(Path(path)) as reader:
        return dict(reader.metadata).get(FLEET_METADATA, {}).get("vehicles", "1") != "1"


def load_fleet(path: str | Path, *, mission: str | None = None) -> RecordedFleet:
    """Read a fleet's recording (``uavtool fly --vehicles N``): every vehicle's observations
    and outputs, under its ``/uavN`` topics; a one-line InputError when anything is missing."""
    path = Path(path)
    with RecordingReader(path) as reader:
        reader.require_metadata(_NEEDED_METADATA)
        meta = dict(reader.metadata)
        if FLEET_METADATA not in meta or CREW_METADATA not in meta:
            raise ReplayInputError(f"{path}: not a fleet's recording (no fleet or crew metadata)")
        cls, ref, params, params_json, tool_version = _mission(meta, path, mission)
        homes = _homes(meta[CREW_METADATA].get("homes_en_m", ""), path)
        target = _target(reader, path)
        vehicles = []
        for k in range(1, len(homes) + 1):
            prefix = vehicle_prefix(k)
            raw_obs, images, outputs = _read_vehicle(reader, path, prefix)
            steps = [data.get("step") for data in raw_obs]
            if any(type(s) is not int for s in steps) or steps != sorted(set(steps)):  # type: ignore[type-var]
                raise ReplayInputError(
                    f"{path}: the observations on {prefix}{OBSERVATIONS} are not numbered in order"
                )
            obs = _decode(path, prefix, raw_obs, images)
            vehicles.append(RecordedVehicle(k, tuple(steps), tuple(obs), tuple(outputs)))  # type: ignore[arg-type]
        truncated = not reader.health.whole
    if target is None and cls.needs_target:
        raise ReplayInputError(f"{path}: the target picture ({TARGET}) is missing")
    every = sorted(s for v in vehicles for s in v.steps)
    if every != list(range(1, len(every) + 1)):
        missing = next(i for i, s in enumerate(every, start=1) if s != i)
        raise ReplayInputError(f"{path}: the fleet's observation {missing} is missing")
    return RecordedFleet(
        path, cls, ref, params, params_json, target, homes, tuple(vehicles), truncated,
        tool_version,
    )  # fmt: skip


def _mission(
    meta: dict[str, dict[str, str]], path: Path, mission: str | None
) -> tuple[type[FlightMission], MissionRef, Any, dict[str, Any], str]:
    ref, params_json = mission_of(meta, source=str(path))
    cls, ref = for_recording(ref, source=str(path), override=mission)
    params = mission_params(cls, params_json, source=f"{path}: recorded parameters")
    tool_version = meta.get("uavtool", {}).get("version", "?")
    return cls, ref, params, params_json, tool_version


def _target(reader: RecordingReader, path: Path) -> U8Array | None:
    if TARGET not in reader.topics():
        return None
    for entry in reader.entries([TARGET]):
        if isinstance(entry.value, CompressedImage):
            return png_decode(entry.value.data, where=f"{path}: target picture")
    return None


def _read_vehicle(
    reader: RecordingReader, path: Path, prefix: str
) -> tuple[list[dict[str, Any]], list[bytes], list[RecordedOutput]]:
    """One vehicle's raw observations, camera frames and outputs (``prefix``: its namespace,
    "" for a one-vehicle recording)."""
    image_t, obs_t, out_t = prefix + IMAGE, prefix + OBSERVATIONS, prefix + OUTPUTS
    images: list[bytes] = []
    raw_obs: list[dict[str, Any]] = []
    outputs: list[RecordedOutput] = []
    topics = [t for t in (image_t, obs_t, out_t) if t in reader.topics()]
    for entry in reader.entries(topics):
        value = entry.value
        if entry.topic == image_t and isinstance(value, CompressedImage):
            images.append(value.data)
        elif entry.topic == obs_t and isinstance(value, JsonDocument):
            raw_obs.append(dict(value.payload))
        elif entry.topic == out_t and isinstance(value, JsonDocument):
            data = dict(value.payload)
            n, step = data.pop("n", None), data.pop("step", None)
            if type(n) is not int or type(step) is not int:
                raise ReplayInputError(
                    f"{path}: output {len(outputs) + 1} on {out_t} has no whole-number n and step"
                )
            if not isinstance(data.get("type"), str):
                raise ReplayInputError(
                    f"{path}: output {len(outputs) + 1} on {out_t} names no type"
                )
            if n != len(outputs) + 1:  # the replay compares them in this order
                raise ReplayInputError(
                    f"{path}: output {len(outputs) + 1} on {out_t} is numbered {n}: "
                    "the outputs were reordered, lost or altered"
                )
            outputs.append(RecordedOutput(n, step, without_nulls(data)))
    _check_counts(reader, path, {obs_t: len(raw_obs), out_t: len(outputs)})
    return raw_obs, images, outputs


def _decode(
    path: Path, prefix: str, raw_obs: list[dict[str, Any]], images: list[bytes]
) -> list[Observation]:
    observations = []
    for data in raw_obs:
        step = data.get("step")
        image = None
        if data.get("type") == "Photo":
            frame = data.get("frame_index", -1)
            if type(frame) is not int or not 0 <= frame < len(images):
                raise ReplayInputError(
                    f"{path}: photo frame {frame!r:.20} (step {step!r:.20}) is missing from "
                    f"{prefix}{IMAGE} ({len(images)} frames recorded)"
                )
            image = png_decode(images[frame], where=f"{path}: frame {frame}")
        try:
            observations.append(decode_observation(data, image))
        except InputError as exc:
            raise ReplayInputError(f"{path}: step {step!r:.20}: {exc}") from None
    return observations


def _homes(text: str, path: Path) -> tuple[tuple[float, float], ...]:
    try:
        value = json.loads(text) if len(text) < 100_000 else None
        homes = tuple((float(e), float(n)) for e, n in value)  # type: ignore[union-attr]
    except (ValueError, TypeError, RecursionError):
        homes = ()
    if not 1 <= len(homes) <= MAX_FLEET or not all(map(math.isfinite, sum(homes, ()))):
        raise ReplayInputError(f"{path}: metadata crew.homes_en_m is malformed")
    return homes


def _check_counts(reader: RecordingReader, path: Path, read: dict[str, int]) -> None:
    """Refuse a flight read with fewer messages on a topic than the file's statistics count
    (the reader raises first for a corrupt chunk; this is the last word)."""
    counts, channels = reader.message_counts, reader.channels
    for topic, got in read.items():
        expected = sum(
            n for cid, n in counts.items() if cid in channels and channels[cid].topic == topic
        )
        if got < expected:
            raise ReplayInputError(
                f"{path}: read {got} of the {expected} messages on {topic} that the file "
                "counts; it cannot be replayed whole"
            )
