"""A recording copied whole, with detections made on its frames added beside its channels:
``/vision/annotations`` as ``foxglove.ImageAnnotations`` (drawn on the frame they share a
timestamp with) and ``/vision/detections`` as JSON."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations
from foxglove_schemas_protobuf.PointsAnnotation_pb2 import PointsAnnotation
from mcap_protobuf.schema import build_file_descriptor_set

from uavtool.recording.errors import create_file, write_failed
from uavtool.recording.files import atomic_output
from uavtool.recording.reader import RecordingReader
from uavtool.recording.recovery import start_copy

ANNOTATIONS = "/vision/annotations"
DETECTIONS = "/vision/detections"
VISION_METADATA = "vision"
DETECTIONS_SCHEMA: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "uavtool.Detections",
    "description": "What a vision function found in one recorded photo. Each detection may "
    "also hold box_px [x_min, y_min, x_max, y_max], polygon_px and points_px ([[x, y], ...]), "
    "pixels from the top left corner.",
    "type": "object",
    "properties": {
        "frame_index": {"type": "integer"},
        "tag": {"type": "string"},
        "time_boot_ms": {"type": "integer"},
        "width_px": {"type": "integer"},
        "height_px": {"type": "integer"},
        "detections": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {"label": {"type": "string"}, "score": {"type": "number"}},
            },
        },
    },
    "required": ["frame_index", "detections"],
}
_COLOUR = (1.0, 0.2, 0.8, 1.0)  # magenta: no scene colour is


def copy_with_detections(
    src: Path,
    dst: Path,
    found: Sequence[tuple[int, Mapping[str, Any]]],
    record: dict[str, str],
    *,
    prefixes: Sequence[str] = (),
) -> None:
    """Write ``dst``: every message of ``src`` as it is, and for each (log time, detections)
    in ``found`` (log-time order) an annotation and a JSON message at that time; ``record``
    becomes the ``vision`` metadata record. ``dst`` appears only once whole. A fleet's
    detections go under each vehicle's topics: ``prefixes`` (``/uav2`` …), one per entry of
    ``found``."""
    with RecordingReader(src) as reader, atomic_output(dst, inputs=[src]) as tmp:
        try:
            with create_file(tmp) as out:
                writer, channel_ids = start_copy(reader, out, (VISION_METADATA, record))
                fds = build_file_descriptor_set(ImageAnnotations).SerializeToString()
                pb_schema = writer.register_schema(
                    ImageAnnotations.DESCRIPTOR.full_name, "protobuf", bytes(fds)
                )
                where = list(prefixes) or [""] * len(found)
                if len(where) != len(found):
                    raise ValueError("one prefix per entry of found")
                named = sorted(set(where)) or [""]
                annotations = {
                    p: writer.register_channel(p + ANNOTATIONS, "protobuf", pb_schema)
                    for p in named
                }
                json_schema = writer.register_schema(
                    "uavtool.Detections", "jsonschema", json.dumps(DETECTIONS_SCHEMA).encode()
                )
                detections = {
                    p: writer.register_channel(p + DETECTIONS, "json", json_schema) for p in named
                }
                pending = [(t, payload, p) for (t, payload), p in zip(found, where, strict=True)]

                def flush(before_ns: int | None) -> None:
                    while pending and (before_ns is None or pending[0][0] < before_ns):
                        t, payload, p = pending.pop(0)
                        data = _annotations(payload, t)
                        writer.add_message(annotations[p], log_time=t, data=data, publish_time=t)
                        text = json.dumps(payload).encode()
                        writer.add_message(detections[p], log_time=t, data=text, publish_time=t)

                for message in reader.messages():
                    flush(message.log_time_ns)
                    writer.add_message(
                        channel_ids[message.channel.id],
                        log_time=message.log_time_ns,
                        data=message.data,
                        publish_time=message.publish_time_ns,
                        sequence=message.sequence,
                    )
                flush(None)
                writer.finish()
        except OSError as exc:
            raise write_failed(dst, exc) from None


def _annotations(payload: Mapping[str, Any], t_ns: int) -> bytes:
    pb = ImageAnnotations()
    for d in payload["detections"]:
        outlines: list[tuple[int, list[list[float]]]] = []
        if "box_px" in d:
            x0, y0, x1, y1 = d["box_px"]
            outlines.append((PointsAnnotation.LINE_LOOP, [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
        if "polygon_px" in d:
            outlines.append((PointsAnnotation.LINE_LOOP, d["polygon_px"]))
        if "points_px" in d:
            outlines.append((PointsAnnotation.POINTS, d["points_px"]))
        for kind, points in outlines:
            p = pb.points.add()
            _stamp(p, t_ns)
            p.type = kind
            p.thickness = 2.0
            p.outline_color.r, p.outline_color.g, p.outline_color.b, p.outline_color.a = _COLOUR
            p.fill_color.SetInParent()  # transparent: outlines only
            for x, y in points:
                point = p.points.add()
                point.x, point.y = x, y
        label = " ".join(part for part in (d.get("label", ""), _score(d.get("score"))) if part)
        if label and outlines:
            x, y = outlines[0][1][0]
            t = pb.texts.add()
            _stamp(t, t_ns)
            t.position.x, t.position.y = x, y
            t.text, t.font_size = label, 14.0
            t.text_color.r, t.text_color.g, t.text_color.b, t.text_color.a = _COLOUR
            t.background_color.a = 0.6
    return bytes(pb.SerializeToString(deterministic=True))


def _score(score: float | None) -> str:
    return "" if score is None else f"{score:.2f}"


def _stamp(pb: Any, t_ns: int) -> None:
    pb.timestamp.seconds, pb.timestamp.nanos = divmod(t_ns, 1_000_000_000)
