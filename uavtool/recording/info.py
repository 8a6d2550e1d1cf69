"""What `uavtool info` reports: duration, topics, frames, file health, and how the recording
ended: a mission's outcome (`uavtool fly`) or what stopped a `uavtool record`."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.recording import foxglove
from uavtool.recording.fleet import split_topic
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import IMAGE
from uavtool.recording.values import CompressedImage
from uavtool.terminal import safe_text

OUTCOME_METADATA = "outcome"  # the record the mission runner writes when it finishes
RECORD_METADATA = "record"  # `uavtool record` writes it first: a flight it did not fly
RECORD_RESULT_METADATA = "record_result"  # … and this one when it stops


@dataclass(frozen=True, slots=True)
class TopicInfo:
    topic: str
    schema_name: str
    message_encoding: str
    count: int
    rate_hz: float


@dataclass(frozen=True, slots=True)
class RecordingInfo:
    path: str
    size_bytes: int
    whole: bool
    indexed: bool  # read from the summary (whole files written with indexes)
    problem: str  # "" when whole
    readable_bytes: int
    partial_chunk: bool  # messages were rescued from a cut chunk
    library: str
    start_ns: int
    end_ns: int
    message_count: int
    frame_count: int  # camera frames (/camera/image), as the outcome's ``frames`` counts them
    topics: tuple[TopicInfo, ...]
    metadata_names: tuple[str, ...]
    outcome: dict[str, str] | None
    mission: str = ""
    """Which mission flew (name, class, version), "" for a recording of no mission."""
    verified: bool = False  # every chunk was read and checked
    summary_problem: str = ""  # why the summary was not used ("" if used or absent)
    damage: tuple[str, ...] = ()  # each corrupt chunk or damaged record, in words
    messages_lost: int = 0  # in the corrupt chunks, as far as their indexes tell
    other_images: tuple[tuple[str, int], ...] = ()  # (topic, count): e.g. the target picture
    from_record: bool = False  # made by `uavtool record`: no mission, so no outcome to expect
    record_result: dict[str, str] | None = None  # what stopped `uavtool record`, if it did stop
    vehicles: tuple[tuple[int, dict[str, str]], ...] = ()
    """A fleet's vehicles: (system id, its outcome record), in system-id order."""

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9


def summarize(path: str | Path, *, verify: bool = True) -> RecordingInfo:
    """Inspect a recording; never fails on a truncated or damaged file (it says so instead).
    ``verify`` reads every chunk and checks its CRC (and the data-section CRC, when there is
    one); without it a whole file's summary alone is read, and only damage outside the chunks
    (metadata records) is found.

    Raises `NotMcapError` if the file is missing, empty or not MCAP.
    """
    with RecordingReader(path) as reader:
        damage = reader.verify() if verify else reader.damage
        lost = sum(d.messages_lost for d in damage)
        health = reader.health
        start_ns, end_ns = reader.time_range_ns
        duration_s = (end_ns - start_ns) / 1e9
        counts = reader.message_counts
        schemas = reader.schemas
        kinds: dict[str, tuple[str, str]] = {}  # topic -> (schema name, message encoding)
        totals: dict[str, int] = {}
        images: dict[str, int] = {}
        image_schema = foxglove.schema_name(CompressedImage)
        for cid, channel in sorted(reader.channels.items()):
            schema = schemas.get(channel.schema_id)
            name = schema.name if schema else ""
            count = counts.get(cid, 0)
            if name == image_schema:
                images[channel.topic] = images.get(channel.topic, 0) + count
            kinds.setdefault(channel.topic, (name, channel.message_encoding))
            totals[channel.topic] = totals.get(channel.topic, 0) + count
        topics = tuple(
            TopicInfo(topic, *kinds[topic], n, n / duration_s if duration_s > 0 else 0.0)
            for topic, n in sorted(totals.items())
        )
        metadata = reader.metadata
        outcome = _last(metadata, OUTCOME_METADATA)
        # A fleet's frames are its vehicles' (/uavK/camera/image), counted as one flight's.
        per_vehicle = [
            t for t in images if split_topic(t) != (None, t) and split_topic(t)[1] == IMAGE
        ]
        fleet_frames = sum(images.pop(t) for t in per_vehicle)
        record_result = _last(metadata, RECORD_RESULT_METADATA)
        return RecordingInfo(
            path=str(path),
            size_bytes=health.size_bytes,
            whole=health.whole,
            indexed=health.indexed,
            problem=health.problem,
            readable_bytes=health.readable_bytes,
            partial_chunk=health.partial_chunk,
            library=reader.library,
            start_ns=start_ns,
            end_ns=end_ns,
            # the summary counts what was written; a scan counts only what it could read
            message_count=sum(counts.values()) + (0 if health.indexed else lost),
            frame_count=images.pop(IMAGE, 0) + fleet_frames,
            other_images=tuple(sorted(images.items())),
            topics=topics,
            metadata_names=tuple(name for name, _ in metadata),
            outcome=outcome,
            mission=_mission(_last(metadata, "mission")),
            from_record=record_result is not None
            or any(name == RECORD_METADATA for name, _ in metadata),
            record_result=record_result,
            vehicles=_vehicles(metadata),
            verified=verify,
            summary_problem=reader.summary_problem,
            damage=tuple(reader.describe(d) for d in damage),
            messages_lost=lost,
        )


def _mission(record: dict[str, str] | None) -> str:
    """The mission a recording's ``mission`` record names; one without a name (before
    missions were plug-ins) flew the built-in search."""
    if record is None:
        return ""
    name = record.get("name", "search")
    version = record.get("version") or record.get("tool_version", "")
    where = ", ".join(
        x for x in (record.get("class", ""), f"version {version}" if version else "") if x
    )
    return f"{name} ({where})" if where else name


def _vehicles(
    metadata: list[tuple[str, dict[str, str]]],
) -> tuple[tuple[int, dict[str, str]], ...]:
    """Each vehicle of a fleet with its outcome record (``outcome.uavK``); of a fleet that
    `uavtool record` recorded, with what was recorded of it (``record_result.uavK``, or
    nothing when the recorder was killed first: the vehicles are those ``record`` names)."""
    found: dict[int, dict[str, str]] = {}
    for name, record in metadata:
        head, _, tail = name.partition(".uav")
        if head in (OUTCOME_METADATA, RECORD_RESULT_METADATA) and tail.isdigit() and len(tail) <= 3:
            found[int(tail)] = dict(record)
    named = _last(metadata, RECORD_METADATA) or {}
    try:
        sysids = json.loads(named.get("vehicle_sysids", "[]")[:10_000])
    except ValueError:
        sysids = []
    for k in sysids if isinstance(sysids, list) else []:
        if type(k) is int and 0 < k < 1000:
            found.setdefault(k, {})
    return tuple(sorted(found.items()))


def _last(metadata: list[tuple[str, dict[str, str]]], name: str) -> dict[str, str] | None:
    return next((dict(r) for n, r in reversed(metadata) if n == name), None)


def damage_problem(info: RecordingInfo) -> str:
    """One line on what is damaged ("" if nothing is): the reason `uavtool info` fails."""
    if info.damage:
        lost = f" ({info.messages_lost} messages lost)" if info.messages_lost else ""
        return (
            f"{len(info.damage)} damaged part(s){lost}, first {info.damage[0]}; "
            f"`uavtool info --recover {info.path} -o fixed.mcap` keeps every good chunk"
        )
    if info.summary_problem:
        return (
            f"{info.summary_problem} (every message is still readable); "
            f"`uavtool info --recover {info.path} -o fixed.mcap` writes a sound summary"
        )
    return ""


def info_json(info: RecordingInfo) -> dict[str, Any]:
    """What `uavtool info --json` prints: every field of ``info``, plus ``duration_s``."""
    data = dataclasses.asdict(info)
    data["duration_s"] = info.duration_s
    data["other_images"] = dict(info.other_images)
    data["vehicles"] = {str(k): v for k, v in info.vehicles}
    return data


def format_info(info: RecordingInfo) -> str:
    """The human-readable report `uavtool info` prints."""
    lines = [f"file:      {info.path} ({info.size_bytes} bytes, written by {info.library or '?'})"]
    if info.damage:
        lost = f", {info.messages_lost} messages lost" if info.messages_lost else ""
        lines.append(f"health:    DAMAGED — {len(info.damage)} part(s) fail their checks{lost}")
        lines.extend(f"           {d}" for d in info.damage)
        lines.append(
            f"           keep every good chunk with: "
            f"uavtool info --recover {info.path} -o fixed.mcap"
        )
        if not info.whole:
            lines.append(f"           and it is TRUNCATED — {info.problem}")
    elif info.whole:
        checked = ", CRCs checked" if info.verified else ", chunks not checked"
        index = "indexed" if info.indexed else "no summary or index"
        if info.summary_problem:
            index = f"{info.summary_problem}: every record read by a scan instead"
        lines.append(f"health:    whole, {index}{checked}")
    else:
        rescued = " (some from a cut chunk)" if info.partial_chunk else ""
        lines.append(f"health:    TRUNCATED — {info.problem}")
        lines.append(
            f"           {info.message_count} messages readable{rescued} from the first "
            f"{info.readable_bytes} bytes; "
            f"recover them with: uavtool info --recover {info.path} -o fixed.mcap"
        )
    lines.append(f"duration:  {info.duration_s:.3f} s")
    readable = (
        f" ({info.message_count - info.messages_lost} readable)" if info.messages_lost else ""
    )
    lines.append(f"messages:  {info.message_count}{readable}")
    others = "".join(f"; {n} on {topic}" for topic, n in info.other_images)
    where = "/uavN" + IMAGE if info.vehicles else IMAGE
    lines.append(f"frames:    {info.frame_count} on {where}{others}")
    if info.mission:
        lines.append(f"mission:   {info.mission}")
    lines.append(_ending(info))
    for sysid, record in info.vehicles:
        if info.from_record and "status" not in record:
            lines.append(f"vehicle {sysid}: {_recorded(record)} (topics /uav{sysid}/…)")
            continue
        said = f"{record.get('status', '?')}: {record.get('reason', '?')}"
        frames = record.get("frames")
        lines.append(
            f"vehicle {sysid}: {said}"
            + (f" ({frames} photos, topics /uav{sysid}/…)" if frames else "")
        )
    if info.metadata_names:
        lines.append("metadata:  " + ", ".join(info.metadata_names))
    lines.append("topics:")
    width = max((len(t.topic) for t in info.topics), default=0)
    for t in info.topics:
        kind = t.schema_name or t.message_encoding
        lines.append(f"  {t.topic:<{width}}  {t.count:>8} msgs  {t.rate_hz:9.2f} Hz  {kind}")
    # Names and values come from the file: no escape sequence of theirs reaches the terminal.
    return "\n".join(safe_text(line) for line in lines)


def _recorded(record: dict[str, str]) -> str:
    """What `uavtool record` recorded of one vehicle of a fleet (``record_result.uavK``)."""
    if not record:
        return "recorded; no result (the recorder was killed before it could write one)"
    counts = ("telemetry", "telemetry samples"), ("frames", "frames"), ("photos", "photos")
    text = ", ".join(f"{record.get(key, '?')} {noun}" for key, noun in counts)
    text += f", {record.get('events', '?')} events"
    gaps = record.get("gaps")
    return f"{text}; incomplete: {gaps}" if gaps else text


def _ending(info: RecordingInfo) -> str:
    """The line on how the recording ended: the mission's outcome, or why `record` stopped."""
    if info.outcome is not None:
        return "outcome:   " + ", ".join(f"{k}={v}" for k, v in info.outcome.items())
    if "import" in info.metadata_names:
        return "imported:  a telemetry log (no mission ran in uavtool, so no outcome)"
    if not info.from_record:
        return "outcome:   unknown (no 'outcome' record: the mission did not finish)"
    r = info.record_result
    if r is None:
        return (
            "recorded:  by uavtool record (no mission); no 'record_result': "
            "the recorder was killed before it could write how it stopped"
        )
    known = ("stopped", "duration_s", "frames", "photos")
    text = (
        f"recorded:  by uavtool record (no mission), stopped: {r.get('stopped', '?')} after "
        f"{r.get('duration_s', '?')} s; {r.get('frames', '?')} frames, "
        f"{r.get('photos', '?')} photos"
    )
    rest = [f"{k}={v}" for k, v in r.items() if k not in known]
    return text + (f" ({', '.join(rest)})" if rest else "")


def truncation(path: str | Path) -> str:
    """One line on where the file ``path`` was cut ("" when it is whole): what `export`,
    `view` and `replay` say after reading what it holds. Raises `CorruptRecordingError` for a
    damaged metadata record, or a data section that fails its CRC (a record outside the
    chunks was changed: what the file says cannot be trusted, though every message may read)."""
    with RecordingReader(path) as reader:
        health = reader.health
        reader.require_metadata({d.name for d in reader.damage if d.name})
    if health.whole:
        return ""
    return (
        f"{path} is truncated ({health.problem}): only what its first {health.readable_bytes} "
        f"of {health.size_bytes} bytes hold was read; `uavtool info --recover {path} -o "
        "fixed.mcap` makes it a whole file"
    )
