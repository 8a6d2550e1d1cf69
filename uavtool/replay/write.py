"""``replay -o``: a new recording with the original's inputs and the replayed outputs, which
``uavtool view`` can show beside the original."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from uavtool.mission.params import to_dict
from uavtool.recording import (
    JsonDocument,
    LogEntry,
    MavlinkFrame,
    RecordingReader,
    RecordingWriter,
)
from uavtool.recording.files import atomic_output
from uavtool.recording.topics import EVENTS, MODEL, OBSERVATIONS, OUTPUTS, PICTURES
from uavtool.replay.load import RecordedOutput
from uavtool.runner.record import MissionRecorder

_REGENERATED = {OUTPUTS, MODEL, PICTURES}


_MISSION_KEYS = ("name", "class", "version")


def write_replay(
    source: Path,
    out: Path,
    outputs: list[RecordedOutput],
    blobs: dict[int, bytes],
    params: Any,
    *,
    outcome: dict[str, str] | None = None,
) -> None:
    """Copy ``source``'s inputs into ``out`` and write ``outputs`` (with each model's GLB from
    ``blobs`` by output number) at the log time of the observation that produced them.
    ``out`` appears only once complete; `SameFileError` if it is ``source``."""
    with RecordingReader(source) as reader, atomic_output(out, inputs=[source]) as tmp:
        records = dict(reader.metadata)
        meta = {
            name: record
            for name, record in records.items()
            if name not in ("uavtool", "outcome", "mission")
        }
        # Which mission it is stays; the parameters are those replayed.
        which = {k: v for k, v in records.get("mission", {}).items() if k in _MISSION_KEYS}
        meta["mission"] = {"params": json.dumps(to_dict(params)), **which}
        meta["replay"] = {"source": str(source)}
        with RecordingWriter(tmp, metadata=meta) as writer:
            recorder = MissionRecorder(writer)
            pending = list(outputs)
            last_t = 0
            for entry in reader.entries():
                topic, value, t = entry.topic, entry.value, entry.log_time_ns
                if topic.startswith("/mavlink/") and not isinstance(value, MavlinkFrame):
                    continue  # the writer rebuilds the decoded views from the raw frames
                if topic in _REGENERATED or (
                    topic == EVENTS and isinstance(value, LogEntry) and value.name == "mission"
                ):
                    continue
                if topic == OBSERVATIONS and isinstance(value, JsonDocument):
                    step = int(value.payload["step"])
                    pending = _flush(recorder, pending, step - 1, last_t or t, blobs)
                    writer.write_json(
                        OBSERVATIONS,
                        value.payload,
                        log_time_ns=t,
                        publish_time_ns=entry.publish_time_ns,
                    )
                    last_t = t
                elif isinstance(value, MavlinkFrame):
                    writer.write_mavlink(
                        value.data,
                        direction=value.direction,
                        log_time_ns=t,
                        publish_time_ns=entry.publish_time_ns,
                    )
                elif isinstance(value, JsonDocument):
                    continue  # other JSON channels: not inputs
                else:
                    writer.write(topic, value, log_time_ns=t, publish_time_ns=entry.publish_time_ns)
            _flush(recorder, pending, 1 << 62, last_t or 1, blobs)
            writer.add_metadata("outcome", outcome or {"status": "replay-diverged"})


def _flush(
    recorder: MissionRecorder,
    pending: list[RecordedOutput],
    up_to_step: int,
    t: int,
    blobs: dict[int, bytes],
) -> list[RecordedOutput]:
    while pending and pending[0].step <= up_to_step:
        out = pending.pop(0)
        recorder.write_output(out.n, out.step, out.data, blob=blobs.get(out.n), log_time_ns=t)
    return pending
