"""Re-fly: fly a recording's configuration again on the built-in vehicle, in lockstep, from
the recording's metadata alone, and compare the new recording with the old one.

Where ``replay --check`` proves the mission reproduces its outputs from recorded observations,
re-flying is the regression test for everything together: the vehicle, the link, the renderer
and the mission. A lockstep flight is a function of its inputs, so the new recording must hold
the same messages, in the same order, with the same times and bytes.
"""

from __future__ import annotations

import dataclasses
import json
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from itertools import zip_longest
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.flight import FlightDescription
from uavtool.plugins import for_recording, mission_params
from uavtool.recording import CompressedImage, RecordingReader
from uavtool.recording.files import refuse_same_file
from uavtool.recording.reader import Message
from uavtool.recording.topics import TARGET
from uavtool.runner.fleet import FleetSummary, fly_fleet
from uavtool.runner.fly import FlightSummary, FlyConfig, fly
from uavtool.runner.runner import Progress
from uavtool.sitl.lockstep import SIM_EPOCH_NS
from uavtool.world import scene_from_dict

# Metadata that names the software, not the flight: a re-flight by a newer version of the
# same code must still compare equal.
_VERSION_KEYS = {("uavtool", "version"), ("mission", "tool_version"), ("mission", "version")}
_DESCRIPTION_RECORDS = frozenset({"mission", "scene", "seeds", "vehicle", "flight"})
"""The records the flight description is stored in (compared as one description)."""


class ReflyInputError(InputError):
    """The recording cannot be re-flown (not a lockstep flight of the built-in vehicle)."""


@dataclass(frozen=True, slots=True)
class ReflyResult:
    """``first_difference`` is None when the new recording equals the old one."""

    recording: Path
    reflown: Path
    messages: int
    first_difference: str | None
    summary: FlightSummary | FleetSummary

    @property
    def identical(self) -> bool:
        return self.first_difference is None


def is_lockstep(path: Path) -> bool:
    """Whether ``path`` is a lockstep flight of the built-in vehicle (one that can be re-flown)."""
    with RecordingReader(path) as reader:
        meta = dict(reader.metadata)
    return meta.get("vehicle", {}).get("clock") == "lockstep" and "flight" in meta


def refly_config(path: Path, *, out: Path, workdir: Path, mission: str | None = None) -> FlyConfig:
    """The :class:`FlyConfig` that made the lockstep recording ``path``, recording to ``out``
    (a target picture the user gave is written into ``workdir``). Raises ReflyInputError.
    ``mission`` (``--mission``) names the mission's class when the recording's is not
    registered here."""
    with RecordingReader(path) as reader:
        reader.require_metadata(("mission", "scene", "flight", "vehicle"))
        reader.require_intact()  # now, not after flying: the comparison needs all of it
        reader.require_decodable()  # ... and a difference must be the flight's, not the file's
        meta = dict(reader.metadata)
        if not is_lockstep(path):
            raise ReflyInputError(
                f"{path}: not a lockstep flight of the built-in vehicle (metadata 'vehicle' "
                "clock is not 'lockstep'); only those can be flown again: make one with "
                "`uavtool fly`"
            )
        d = FlightDescription.from_metadata(meta, source=str(path))
        if d.camera != "sim":
            # Anything else is a device or a URL for OpenCV/FFmpeg to open: never from a file.
            raise ReflyInputError(
                f"{path}: recorded with the camera {d.camera[:40]!r}; only a flight with the "
                "simulated camera can be flown again"
            )
        if d.scene is None:
            raise ReflyInputError(f"{path}: metadata 'scene' holds no scene to fly in")
        cls, ref = for_recording(d.mission, source=str(path), override=mission)
        return FlyConfig(
            scene=scene_from_dict(d.scene, source=f"{path}: scene"),
            camera="sim",
            record=out,
            mission=ref.name if mission is None else mission,
            params=mission_params(cls, d.params, source=f"{path}: mission parameters"),
            vehicle_params=d.vehicle_params,
            seed=d.seed,
            noise=d.noise,
            wind=d.wind,
            link_outages_s=d.link_outages_s,
            hfov_deg=d.hfov_deg,
            size_px=d.size_px,
            target=_target_file(reader, path, workdir) if d.target == "file" else None,
            no_gimbal=d.no_gimbal,
            vehicles=d.vehicles,
            offset_line=d.offset_line,
            homes_m=d.homes_m,
        )


def refly(
    path: str | Path,
    *,
    out: Path | None = None,
    progress: Progress | None = None,
    compare: bool = True,
    mission: str | None = None,
) -> ReflyResult:
    """Fly ``path``'s configuration again (to ``out``, or a temporary file that is removed)
    and compare the two recordings message by message."""
    path = Path(path)
    if out is not None:
        refuse_same_file(out, [path])
    with tempfile.TemporaryDirectory(prefix="uavtool-refly-") as tmp:
        work = Path(tmp)
        target = out if out is not None else work / "reflown.mcap"
        config = refly_config(path, out=target, workdir=work, mission=mission)
        summary: FlightSummary | FleetSummary = (
            fly_fleet(config) if config.vehicles > 1 else fly(config, progress=progress)
        )
        count, diff = compare_recordings(path, target) if compare else (0, None)
    return ReflyResult(path, target, count, diff, summary)


def compare_recordings(old: Path, new: Path) -> tuple[int, str | None]:
    """(messages compared, the first difference in words or None) between two recordings:
    metadata records (software versions aside), then every message in file order — topic,
    log and publish time, sequence and bytes. The MCAP header, which names library versions,
    is not compared."""
    with RecordingReader(old) as a, RecordingReader(new) as b:
        diff = _metadata_difference(a.metadata, b.metadata)
        if diff is not None:
            return 0, diff
        count = 0
        for was, now in zip_longest(a.messages(), b.messages()):
            if was is None or now is None:
                which, extra = ("re-flown", now) if was is None else ("recorded", was)
                assert extra is not None
                return count, f"the {which} flight has more messages, from {_where(count, extra)}"
            diff = _message_difference(was, now)
            if diff is not None:
                return count, f"{_where(count, was)}: {diff}"
            count += 1
    return count, None


def _where(index: int, m: Message) -> str:
    t = (m.log_time_ns - SIM_EPOCH_NS) / 1e9
    return f"message {index} ({m.channel.topic}, vehicle time {t:.3f} s)"


def _message_difference(was: Message, now: Message) -> str | None:
    checks: list[tuple[str, Callable[[Message], Any]]] = [
        ("topic", lambda m: m.channel.topic),
        ("log_time", lambda m: m.log_time_ns),
        ("publish_time", lambda m: m.publish_time_ns),
        ("sequence", lambda m: m.sequence),
    ]
    for name, get in checks:
        if get(was) != get(now):
            return f"{name} {get(was)!r} recorded, {get(now)!r} re-flown"
    if was.data == now.data:
        return None
    if was.channel.message_encoding == "json":
        try:
            return _json_difference(json.loads(was.data), json.loads(now.data))
        except (ValueError, RecursionError):
            pass  # not JSON on one side: compare the bytes
    offset = next(i for i, (x, y) in enumerate(zip_longest(was.data, now.data)) if x != y)
    return f"bytes differ from offset {offset} ({len(was.data)} recorded, {len(now.data)} re-flown)"


def _json_difference(was: Any, now: Any, where: str = "") -> str:
    if isinstance(was, dict) and isinstance(now, dict):
        for key in sorted(set(was) | set(now)):
            if was.get(key) != now.get(key):
                return _json_difference(was.get(key), now.get(key), f"{where}.{key}")
    if isinstance(was, list) and isinstance(now, list) and len(was) == len(now):
        for i, (x, y) in enumerate(zip(was, now, strict=True)):
            if x != y:
                return _json_difference(x, y, f"{where}[{i}]")
    return f"{where.lstrip('.') or 'value'}: {_short(was)} recorded, {_short(now)} re-flown"


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _metadata_difference(
    was: list[tuple[str, dict[str, str]]], now: list[tuple[str, dict[str, str]]]
) -> str | None:
    """The first difference in what the two flights were (their descriptions, software
    versions aside; an older recording's describes the same flight in fewer words), then in
    any other metadata record (every record, for recordings that describe no flight)."""
    described = [{"mission", "vehicle", "flight"} <= {n for n, _ in m} for m in (was, now)]
    rest_a, rest_b = was, now
    if all(described):
        try:
            old = _comparable(FlightDescription.from_metadata(dict(was), source="recorded"))
            new = _comparable(FlightDescription.from_metadata(dict(now), source="re-flown"))
        except InputError as exc:
            return f"metadata: {exc}"
        for f in dataclasses.fields(FlightDescription):
            x, y = getattr(old, f.name), getattr(new, f.name)
            if x != y:
                if isinstance(x, dict) and isinstance(y, dict):
                    return f"metadata {f.name}: {_json_difference(x, y)}"
                return f"metadata {f.name}: {_short_any(x)} recorded, {_short_any(y)} re-flown"
        rest_a = [(n, r) for n, r in was if n not in _DESCRIPTION_RECORDS]
        rest_b = [(n, r) for n, r in now if n not in _DESCRIPTION_RECORDS]
    if [n for n, _ in rest_a] != [n for n, _ in rest_b]:
        return (
            f"metadata records {[n for n, _ in rest_a]} recorded, {[n for n, _ in rest_b]} re-flown"
        )
    for (name, rec_a), (_, rec_b) in zip(rest_a, rest_b, strict=True):
        x = {k: v for k, v in rec_a.items() if (name, k) not in _VERSION_KEYS}
        y = {k: v for k, v in rec_b.items() if (name, k) not in _VERSION_KEYS}
        if x != y:
            key = next(k for k in sorted(set(x) | set(y)) if x.get(k) != y.get(k))
            try:  # a JSON value (the parameters): name the field inside it
                inner = _json_difference(json.loads(x[key]), json.loads(y[key]))
            except (KeyError, TypeError, ValueError, RecursionError):
                inner = f"{_short(x.get(key))} recorded, {_short(y.get(key))} re-flown"
            return f"metadata {name}.{key}: {inner}"
    return None


def _comparable(d: FlightDescription) -> FlightDescription:
    """``d`` without the versions of the software that flew it."""
    return dataclasses.replace(d, mission=dataclasses.replace(d.mission, version=""))


def _short_any(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _target_file(reader: RecordingReader, path: Path, workdir: Path) -> Path:
    for entry in reader.entries([TARGET]):
        if isinstance(entry.value, CompressedImage):
            file = workdir / "target.png"
            file.write_bytes(entry.value.data)
            return file
    raise ReflyInputError(f"{path}: the target picture ({TARGET}) is missing")
