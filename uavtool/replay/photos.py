"""``replay --vision-only`` of a recording with no mission in it (``uavtool record``): every
photo vectorized and compared with a target picture, and a new recording with the results.

The photos are the frames of ``/camera/frames`` marked as photos (every frame when none is);
each is judged as the mission judges a photo above a point of interest: the shape the photo is
centred on, against the target's largest shape (:func:`uavtool.mission.analysis.judge`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.camera import CameraPose, Intrinsics
from uavtool.images import png_decode
from uavtool.mission import Params
from uavtool.mission.analysis import (
    Judgement,
    judge,
    nadir_shapes,
    side_shapes,
    stepped,
    target_shapes,
)
from uavtool.mission.codec import decode_camera, encode_output
from uavtool.mission.outputs import Recognition, Shapes
from uavtool.mission.params import to_dict
from uavtool.recording import (
    CompressedImage,
    JsonDocument,
    MavlinkFrame,
    RecordingReader,
    RecordingWriter,
)
from uavtool.recording.files import atomic_output
from uavtool.recording.topics import FRAMES, IMAGE, TARGET, VISION
from uavtool.replay.load import ReplayInputError
from uavtool.vision import Shape

SIDE_PITCH_DEG = -45.0
"""A photo pitched above this looks at walls: vectorized as the mission's side photos."""
_VISION_SCHEMA = {
    "title": "uavtool.Output",
    "description": "replay --vision-only: per photo, its Shapes and its Recognition against "
    "the target (frame_index -1: the target picture's shapes).",
    "type": "object",
    "properties": {"type": {"type": "string"}, "frame_index": {"type": "integer"}},
    "required": ["type", "frame_index"],
}


@dataclass(frozen=True, slots=True)
class PhotoResult:
    """One photo through vision: its shapes and the judgement against the target."""

    frame_index: int
    tag: str
    photo: int
    pose: CameraPose
    log_time_ns: int
    shapes: tuple[Shape, ...]
    judgement: Judgement

    def describe(self) -> str:
        x, y, z = self.pose.pos_enu_m
        j = self.judgement
        verdict = "MATCH" if j.matched else "no match"
        score = f"score {j.score:.3f} {verdict}" if j.candidate >= 0 else "nothing centred"
        return (
            f"frame {self.frame_index} ({self.tag}) at E {x:.1f} N {y:.1f} U {z:.1f} m: "
            f"{len(self.shapes)} shapes, {score}"
        )


@dataclass(frozen=True, slots=True)
class PhotoAnalysis:
    results: tuple[PhotoResult, ...]
    target_shapes: tuple[Shape, ...]
    all_frames: bool
    """No frame was marked as a photo: every frame was analysed."""

    @property
    def matches(self) -> tuple[PhotoResult, ...]:
        return tuple(r for r in self.results if r.judgement.matched)


def is_recorded_flight(path: str | Path) -> bool:
    """Whether ``path`` holds a flight from ``uavtool record`` (camera frames, no mission)."""
    with RecordingReader(path) as reader:
        return FRAMES in reader.topics()


def analyse_photos(path: str | Path, target_png: bytes, params: Params) -> PhotoAnalysis:
    """Vectorize every photo of ``path`` and judge it against ``target_png``. Raises
    ReplayInputError when the file has no frames or a frame's image is missing."""
    path = Path(path)
    target_rgb = png_decode(target_png, where="--target")
    shapes_t, target = target_shapes(params, target_rgb)
    target_stepped = stepped(target_rgb, target)
    frames = _frames(path)
    photos = [(rec, png, t) for rec, png, t in frames if int(rec.get("photo", -1)) >= 0]
    chosen = photos or frames
    results = []
    for rec, png, t_ns in chosen:
        pose, intrinsics = _camera(rec)
        image = png_decode(png, where=f"{path}: frame {rec.get('frame_index')}")
        side = pose.pitch_deg > SIDE_PITCH_DEG
        shapes = side_shapes(params, image) if side else nadir_shapes(params, image)
        results.append(
            PhotoResult(
                int(rec["frame_index"]),
                str(rec.get("tag", "")),
                int(rec.get("photo", -1)),
                pose,
                t_ns,
                shapes,
                judge(params, target, shapes, intrinsics, target_stepped=target_stepped),
            )
        )
    return PhotoAnalysis(tuple(results), shapes_t, all_frames=not photos)


def write_analysis(
    source: Path, out: Path, target_png: bytes, analysis: PhotoAnalysis, params: Params
) -> None:
    """A copy of ``source`` with the target picture on ``/mission/target`` and, on
    ``/vision/results``, each photo's ``Shapes`` and ``Recognition`` at its frame's log time.
    ``out`` appears only once complete; `SameFileError` if it is ``source``."""
    with RecordingReader(source) as reader, atomic_output(out, inputs=[source]) as tmp:
        schemas = reader.schemas
        json_schemas = {
            c.topic: schemas[c.schema_id]
            for c in reader.channels.values()
            if c.schema_id in schemas and c.message_encoding == "json"
        }
        meta = {n: r for n, r in reader.metadata if n != "uavtool"}
        meta["vision_only"] = {"source": source.name, "params": json.dumps(to_dict(params))}
        start_ns = max(reader.time_range_ns[0], 1)
        with RecordingWriter(tmp, metadata=meta) as writer:
            writer.write(
                TARGET, CompressedImage(target_png, frame_id="target"), log_time_ns=start_ns
            )
            writer.add_json_topic(VISION, schema_name="uavtool.Output", schema=_VISION_SCHEMA)
            target = Shapes(-1, "target", analysis.target_shapes)
            writer.write_json(VISION, encode_output(target), log_time_ns=start_ns)
            pending = sorted(analysis.results, key=lambda r: r.log_time_ns)
            for entry in reader.entries():
                topic, value, t = entry.topic, entry.value, entry.log_time_ns
                while pending and pending[0].log_time_ns < t:
                    _write_result(writer, pending.pop(0))
                if isinstance(value, MavlinkFrame):
                    writer.write_mavlink(value.data, direction=value.direction, log_time_ns=t)
                elif topic.startswith("/mavlink/") or topic in (VISION, TARGET):
                    continue  # decoded views are rebuilt from the raw frames; results anew
                elif isinstance(value, JsonDocument):
                    schema = json_schemas[topic]
                    writer.add_json_topic(
                        topic, schema_name=schema.name, schema=json.loads(schema.data)
                    )
                    writer.write_json(topic, value.payload, log_time_ns=t)
                else:
                    writer.write(topic, value, log_time_ns=t)
            for result in pending:
                _write_result(writer, result)


def _write_result(writer: RecordingWriter, r: PhotoResult) -> None:
    j = r.judgement
    t = r.log_time_ns
    writer.write_json(VISION, encode_output(Shapes(r.frame_index, r.tag, r.shapes)), log_time_ns=t)
    recognition = Recognition(
        r.frame_index, max(r.photo, 0), j.scores, j.candidate, j.score, j.matched, j.mirror_score
    )
    writer.write_json(VISION, encode_output(recognition), log_time_ns=t)


def _frames(path: Path) -> list[tuple[dict[str, Any], bytes, int]]:
    """``(frame record, PNG, log time)`` of every frame, in order."""
    images: list[bytes] = []
    records: list[tuple[dict[str, Any], int]] = []
    with RecordingReader(path) as reader:
        if FRAMES not in reader.topics():
            raise ReplayInputError(
                f"{path}: no {FRAMES}: not a recording of `uavtool record` with a camera"
            )
        for entry in reader.entries([IMAGE, FRAMES]):
            if isinstance(entry.value, CompressedImage):
                images.append(entry.value.data)
            elif isinstance(entry.value, JsonDocument):
                records.append((dict(entry.value.payload), entry.log_time_ns))
    out = []
    for rec, t in records:
        index = int(rec.get("frame_index", -1))
        if not 0 <= index < len(images):
            raise ReplayInputError(
                f"{path}: frame {index} is missing from {IMAGE} ({len(images)} images recorded)"
            )
        out.append((rec, images[index], t))
    if not out:
        raise ReplayInputError(f"{path}: no camera frames recorded")
    return out


def _camera(rec: dict[str, Any]) -> tuple[CameraPose, Intrinsics]:
    try:
        return decode_camera(rec)
    except (KeyError, TypeError, ValueError) as exc:
        raise ReplayInputError(f"frame {rec.get('frame_index')}: bad pose: {exc}") from None
