"""A recording's *content* is untrusted too: an observation crafted to be JSON nested a
hundred thousand deep, or not UTF-8 at all, is one line and exit 2 in every command that
decodes it (replay --check, replay --refly, view) — never a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from mcap.reader import make_reader
from mcap.writer import Writer

from uavtool.cli import cli

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def _with_observation(path: Path, data: bytes, *, nth: int = 3) -> Path:
    """The golden flight with its ``nth`` observation's bytes replaced by ``data``."""
    with GOLDEN.open("rb") as src, path.open("wb") as dst:
        reader = make_reader(src)
        header = reader.get_header()
        writer = Writer(dst)
        writer.start(profile=header.profile, library=header.library)
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        seen = 0
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(
                    schema.name, schema.encoding, schema.data
                )
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(
                    channel.topic,
                    channel.message_encoding,
                    schemas.get(channel.schema_id, 0),
                    channel.metadata,
                )
            body = message.data
            if channel.topic == "/mission/observations":
                seen += 1
                if seen == nth:
                    body = data
            writer.add_message(
                channels[channel.id], message.log_time, body, message.publish_time, message.sequence
            )
        for record in reader.iter_metadata():
            writer.add_metadata(record.name, record.metadata)
        writer.finish()
    return path


@pytest.mark.parametrize(
    "data", [b"[" * 100_000, b"\xff\xfe not text", b'{"step": 3, "type": "Photo"'], ids=str
)
@pytest.mark.parametrize(
    "command",
    [["replay", "--check"], ["replay", "--refly"], ["view", "--save", "{tmp}/v.rrd"]],
    ids=lambda c: " ".join(c[:2]),
)
def test_a_crafted_observation_is_one_line_and_exit_2(
    tmp_path: Path, data: bytes, command: list[str]
) -> None:
    crafted = _with_observation(tmp_path / "crafted.mcap", data)
    args = [a.replace("{tmp}", str(tmp_path)) for a in command]
    result = CliRunner().invoke(cli, [args[0], str(crafted), *args[1:]])
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(
        result.exception
    )
    assert "crafted.mcap" in result.output and "Traceback" not in result.output
    assert "identical" not in result.output
