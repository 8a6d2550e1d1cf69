"""Rewrite whatever a (truncated) recording still holds as a whole, indexed MCAP file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter

from uavtool.recording.errors import create_file, write_failed
from uavtool.recording.files import atomic_output
from uavtool.recording.reader import RecordingReader
from uavtool.recording.writer import LIBRARY

RECOVERED_METADATA = "recovered"


@dataclass(frozen=True, slots=True)
class RecoverResult:
    messages: int
    channels: int
    metadata: int
    problem: str  # what was wrong with the source ("" if it was whole)
    dropped: tuple[str, ...] = ()  # each damaged chunk or record left out, in words
    messages_lost: int = 0  # in the dropped chunks, as far as their indexes tell


def recover(src: str | Path, dst: str | Path) -> RecoverResult:
    """Copy every readable schema, channel, metadata record and message of ``src`` (in file
    order, times and sequence numbers kept) into a new, whole file ``dst``; chunks that fail
    their checks and metadata records that do not parse are left out. Adds a ``recovered``
    metadata record naming the source, its problem and what was dropped. ``dst`` appears
    only once complete; raises `SameFileError` if it is ``src``."""
    with RecordingReader(src, skip_damaged=True) as reader:
        damage = reader.verify()
        dropped = tuple(reader.describe(d) for d in damage)
        problem = reader.health.problem
        record = {"source": Path(src).name, "problem": problem}
        if dropped:
            record["dropped"] = "; ".join(dropped)
        try:  # the last buffered bytes are written when the file closes: a full disk then
            with atomic_output(dst, inputs=[src]) as tmp, create_file(tmp) as out:
                count, channels, metadata = _copy(reader, out, record)
        except OSError as exc:
            raise write_failed(dst, exc) from None
    lost = sum(d.messages_lost for d in damage)
    return RecoverResult(count, channels, metadata, problem, dropped, lost)


def start_copy(
    reader: RecordingReader, out: Any, record: tuple[str, dict[str, str]]
) -> tuple[Any, dict[int, int]]:
    """An MCAP writer on ``out`` with ``reader``'s metadata (plus ``record``), schemas and
    channels registered, ready for the messages; and the channel ids, reader's → writer's."""
    writer: Any = McapWriter(out, compression=CompressionType.ZSTD)
    writer.start(profile="", library=LIBRARY)
    for name, values in reader.metadata:
        writer.add_metadata(name, values)
    writer.add_metadata(*record)
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
    return writer, channel_ids


def _copy(reader: RecordingReader, out: Any, recovered: dict[str, str]) -> tuple[int, int, int]:
    writer, channel_ids = start_copy(reader, out, (RECOVERED_METADATA, recovered))
    metadata = reader.metadata
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
    return count, len(channel_ids), len(metadata)
