"""Every Foxglove message a recording holds is valid under Foxglove's own JSON schemas
(``@foxglove/schemas`` from npm, 2.x), not only decodable as Protobuf: Foxglove, Lichtblick
and anything that reads the JSON form find every field they require.

Each Protobuf message is turned into the JSON form those schemas describe (every field, as
proto3 has it; time and duration as ``{sec, nsec}``; bytes base64; enums as their numbers) and
checked with the ``jsonschema`` package. A sub-message left unset is left out, as a JSON
encoder leaves it out: a required one then fails."""

from __future__ import annotations

import base64
import json
import shutil
import subprocess
from collections import Counter
from functools import cache
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

from tests.npm_cache import npm_cache, npm_installed
from uavtool.recording import RecordingReader
from uavtool.recording.foxglove import _PB_CLASS

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden"
PACKAGE = "@foxglove/schemas@2.1.0"


@cache
def _schemas() -> dict[str, Any] | None:
    """Foxglove's JSON schemas by message name (``foxglove.LocationFix``), from npm's
    ``@foxglove/schemas`` (installed on first use into ``$UAVTOOL_NPM_CACHE``); None without
    node or npm."""
    if shutil.which("node") is None or shutil.which("npm") is None:
        return None
    folder = npm_cache() / PACKAGE.replace("/", "-")
    npm_installed(
        folder, PACKAGE, folder / "node_modules" / "@foxglove" / "schemas" / "package.json"
    )
    script = "console.log(JSON.stringify(require('@foxglove/schemas/jsonschema')))"
    out = subprocess.run(
        ["node", "-e", script],
        cwd=folder, check=True, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    by_name = json.loads(out.stdout)
    return {schema["title"]: schema for schema in by_name.values() if "title" in schema}


def as_json(message: Message) -> dict[str, Any]:
    """``message`` in the JSON form Foxglove's JSON schemas describe."""
    out: dict[str, Any] = {}
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.is_repeated:
            out[field.name] = [_value(field, v) for v in value]
        elif field.type == FieldDescriptor.TYPE_MESSAGE and not message.HasField(field.name):
            continue  # unset: a JSON encoder writes nothing
        else:
            out[field.name] = _value(field, value)
    return out


def _value(field: FieldDescriptor, value: Any) -> Any:
    if field.type == FieldDescriptor.TYPE_MESSAGE:
        name = field.message_type.full_name
        if name in ("google.protobuf.Timestamp", "google.protobuf.Duration"):
            return {"sec": value.seconds, "nsec": value.nanos}
        return as_json(value)
    if field.type == FieldDescriptor.TYPE_BYTES:
        return base64.b64encode(value).decode()
    return value


def _foxglove_messages(path: Path) -> list[tuple[str, str, Message]]:
    classes = {cls.DESCRIPTOR.full_name: cls for cls in _PB_CLASS.values()}
    found = []
    with RecordingReader(path) as reader:
        for message in reader.messages():
            schema = message.schema
            if schema is None or schema.name not in classes:
                continue
            pb = classes[schema.name]()
            pb.ParseFromString(message.data)
            found.append((message.channel.topic, schema.name, pb))
    return found


@pytest.mark.parametrize("golden", ["paper.mcap", "paper-wind.mcap"])
def test_every_foxglove_message_is_valid_under_foxglove_json_schemas(golden: str) -> None:
    schemas = _schemas()
    if schemas is None:
        pytest.skip("node and npm are needed to fetch @foxglove/schemas")
    messages = _foxglove_messages(GOLDEN / golden)
    assert {name for _, name, _ in messages} >= {
        "foxglove.CompressedImage",
        "foxglove.CameraCalibration",
        "foxglove.FrameTransform",
        "foxglove.LocationFix",
        "foxglove.PosesInFrame",
        "foxglove.Log",
        "foxglove.SceneUpdate",
    }
    rejected: Counter[str] = Counter()
    first: dict[str, str] = {}
    for topic, name, pb in messages:
        validator = jsonschema.validators.validator_for(schemas[name])(schemas[name])
        errors = list(validator.iter_errors(as_json(pb)))
        if errors:
            key = f"{topic} ({name})"
            rejected[key] += 1
            first.setdefault(key, f"{list(errors[0].absolute_path)}: {errors[0].message}")
    assert not rejected, {k: (n, first[k]) for k, n in rejected.items()}


def test_the_converter_leaves_an_unset_sub_message_out() -> None:
    """So that a required field left unset is caught, not filled in by the test."""
    schemas = _schemas()
    if schemas is None:
        pytest.skip("node and npm are needed to fetch @foxglove/schemas")
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

    update = SceneUpdate()
    update.entities.add().id = "x"
    schema = schemas["foxglove.SceneUpdate"]
    errors = list(jsonschema.validators.validator_for(schema)(schema).iter_errors(as_json(update)))
    assert any("'lifetime' is a required property" in e.message for e in errors)


def test_vision_annotations_are_valid_under_foxglove_json_schemas() -> None:
    """The detections ``replay --vision`` draws over each photo (`foxglove.ImageAnnotations`):
    boxes, polygons, points and labels."""
    schemas = _schemas()
    if schemas is None:
        pytest.skip("node and npm are needed to fetch @foxglove/schemas")
    from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations

    from uavtool.recording.annotations import _annotations

    payload = {
        "detections": [
            {"box_px": [1, 2, 30, 40], "label": "roof", "score": 0.9},
            {"polygon_px": [[0, 0], [5, 0], [5, 5]], "points_px": [[1, 1]]},
        ]
    }
    pb = ImageAnnotations.FromString(_annotations(payload, 1_767_225_600_000_000_000))
    schema = schemas["foxglove.ImageAnnotations"]
    validator = jsonschema.validators.validator_for(schema)(schema)
    assert [e.message for e in validator.iter_errors(as_json(pb))] == []
