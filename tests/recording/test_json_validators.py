"""A standard JSON Schema validator (the ``jsonschema`` package, draft 2020-12) accepts every
message of every JSON channel of every golden against the schema the channel carries — the
null rule: a field with no value is left out, never written as ``null`` where the schema says
number."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

from uavtool.recording import RecordingReader
from uavtool.recording.schemas import MavlinkDecoder, mavlink_schema

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


@pytest.mark.parametrize("path", GOLDEN, ids=[p.name for p in GOLDEN])
def test_every_json_message_validates(path: Path) -> None:
    validators: dict[int, Draft202012Validator] = {}
    checked = 0
    with RecordingReader(path) as reader:
        for message in reader.messages():
            channel = message.channel
            if channel.message_encoding != "json":
                continue
            validator = validators.get(channel.schema_id)
            if validator is None:
                schema = json.loads(reader.schemas[channel.schema_id].data)
                Draft202012Validator.check_schema(schema)
                validator = validators[channel.schema_id] = Draft202012Validator(schema)
            errors = list(validator.iter_errors(json.loads(message.data)))
            assert not errors, f"{channel.topic}: {errors[0].message} at {list(errors[0].path)}"
            checked += 1
    assert checked > 10_000 and len(validators) > 20


def test_a_nan_field_is_left_out_and_not_required() -> None:
    decoder = MavlinkDecoder()
    msg = decoder._mav.command_long_encode(1, 1, 400, 0, 1.0, 0, 0, 0, float("nan"), 0, 0)
    frame = bytes(msg.pack(decoder._mav))
    decoded = decoder.decode(frame)
    assert decoded is not None
    _, name, payload = decoded
    assert name == "COMMAND_LONG" and "param5" not in payload and payload["param1"] == 1.0
    schema = json.loads(mavlink_schema("ardupilotmega", 76)[1])
    assert "param5" not in schema["required"] and "command" in schema["required"]
    Draft202012Validator(schema).validate(payload)
