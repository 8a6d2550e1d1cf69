"""Rewrite whatever a (truncated) recording still holds as a whole, indexed MCAP file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter

from uavtool.recording.errors import RecordingError, create_file
from uavtool.recording.reader import RecordingReader
from uavtool.recording.writer import LIBRARY

RECOVERED_METADATA = "recovered"


@dataclass(frozen=True, slots=True)
class RecoverResult:
    messages: int
    channels: int
    metadata: int
    problem: str  # what was wrong with the source ("" if it was whole)


def recover(src: str | Path, dst: str | Path) -> RecoverResult:
    """Copy every readable schema, channel, metadata record and message of ``src`` (in file
    order, times and sequence numbers kept) into a new, whole file ``dst``. Adds a
    ``recovered`` metadata record naming the source and its problem."""
    if Path(src).resolve() == Path(dst).resolve():
        raise RecordingError(dst, "the output must not be the file being recovered")
    with RecordingReader(src) as reader:
        problem = reader.health.problem
        with create_file(dst) as out:
            writer: Any = McapWriter(out, compression=CompressionType.ZSTD)
            writer.start(profile="", library=LIBRARY)
            metadata = reader.metadata
            for name, record in metadata:
                writer.add_metadata(name, record)
            writer.add_metadata(RECOVERED_METADATA, {"source": Path(src).name, "problem": problem})
            schema_ids = {0: 0}
            for sid, schema in sorted(reader.schemas.items()):
                schema_ids[sid] = writer.register_schema(schema.name, schema.encoding, schema.data)
            channel_ids = {}
            for cid, channel in sorted(reader.channels.items()):
                channel_ids[cid] = writer.register_channel(
                    channel.topic,
                    channel.message_encoding,
                    schema_ids.get(channel.schema_id, 0),
                    dict(channel.metadata),
                )
            count = 0
            for message in reader.messages():
                writer.add_message(
                    channel_ids[message.channel.id],
                    log_time=message.log_time_ns,
                    data=message.data,
                    publish_time=message.publish_time_ns,
                    sequence=message.sequence,
                )
                count += 1
            writer.finish()
    return RecoverResult(count, len(channel_ids), len(metadata), problem)
