"""A recorded flight as replay needs it: the mission and its parameters, the target picture
(if the mission has one), every observation in the order the mission consumed it (photos with
their pixels), and every recorded output. Nothing else is read: not the scene, not the
vehicle, not the network."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.flight import mission_of
from uavtool.images import png_decode
from uavtool.mission import FlightMission, Observation
from uavtool.mission.codec import decode_observation, without_nulls
from uavtool.mission.observations import U8Array
from uavtool.plugins import MissionRef, for_recording, mission_params
from uavtool.recording import CompressedImage, JsonDocument, RecordingReader
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
            raise ReplayInputError(
                f"{path}: not a mission recording (no mission parameters or "
                f"{OBSERVATIONS}); record one with `uavtool fly`"
            )
        ref, params_json = mission_of(meta, source=str(path))
        cls, ref = for_recording(ref, source=str(path), override=mission)
        params = mission_params(cls, params_json, source=f"{path}: recorded parameters")
        tool_version = meta.get("uavtool", {}).get("version", "?")
        target: U8Array | None = None
        images: list[bytes] = []
        raw_obs: list[dict[str, Any]] = []
        outputs: list[RecordedOutput] = []
        topics = [t for t in (TARGET, IMAGE, OBSERVATIONS, OUTPUTS) if t in reader.topics()]
        for entry in reader.entries(topics):
            value = entry.value
            if entry.topic == TARGET and isinstance(value, CompressedImage):
                target = png_decode(value.data, where=f"{path}: target picture")
            elif entry.topic == IMAGE and isinstance(value, CompressedImage):
                images.append(value.data)
            elif entry.topic == OBSERVATIONS and isinstance(value, JsonDocument):
                raw_obs.append(dict(value.payload))
            elif entry.topic == OUTPUTS and isinstance(value, JsonDocument):
                data = dict(value.payload)
                n, step = data.pop("n", None), data.pop("step", None)
                if type(n) is not int or type(step) is not int:
                    raise ReplayInputError(
                        f"{path}: output {len(outputs) + 1} on {OUTPUTS} has no whole-number "
                        "n and step"
                    )
                if not isinstance(data.get("type"), str):
                    raise ReplayInputError(
                        f"{path}: output {len(outputs) + 1} on {OUTPUTS} names no type"
                    )
                if n != len(outputs) + 1:  # the replay compares them in this order
                    raise ReplayInputError(
                        f"{path}: output {len(outputs) + 1} on {OUTPUTS} is numbered {n}: "
                        "the outputs were reordered, lost or altered"
                    )
                outputs.append(RecordedOutput(n, step, without_nulls(data)))
        truncated = not reader.health.whole
        _check_counts(reader, path, {OBSERVATIONS: len(raw_obs), OUTPUTS: len(outputs)})
    if target is None and cls.needs_target:
        raise ReplayInputError(f"{path}: the target picture ({TARGET}) is missing")
    observations = []
    for i, data in enumerate(raw_obs, start=1):
        if data.get("step") != i:
            raise ReplayInputError(
                f"{path}: observation {i} is missing (next recorded is step {data.get('step')})"
            )
        image = None
        if data.get("type") == "Photo":
            frame = data.get("frame_index", -1)
            if type(frame) is not int or not 0 <= frame < len(images):
                raise ReplayInputError(
                    f"{path}: photo frame {frame!r:.20} (step {i}) is missing from {IMAGE} "
                    f"({len(images)} frames recorded)"
                )
            image = png_decode(images[frame], where=f"{path}: frame {frame}")
        try:
            observations.append(decode_observation(data, image))
        except InputError as exc:
            raise ReplayInputError(f"{path}: step {i}: {exc}") from None
    return RecordedFlight(
        path,
        cls,
        ref,
        params,
        params_json,
        target,
        tuple(observations),
        tuple(outputs),
        truncated,
        tool_version,
    )


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
