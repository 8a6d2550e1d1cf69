"""`RecordingReader`: iterate a recording by topic and time range, whole or truncated.

Messages come in file order, which is the order they were written: for replay that is the
order the mission consumed its observations. `entries` decodes them to our value types.
"""

from __future__ import annotations

import json
import mmap
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from uavtool.recording import foxglove
from uavtool.recording.errors import (
    NotMcapError,
    RecordingError,
    TopicNotFoundError,
    UnknownSchemaError,
)
from uavtool.recording.layout import (
    Block,
    Channel,
    Health,
    Layout,
    NotMcap,
    Op,
    Schema,
    chunk_payload,
    decompress,
    iter_records,
    parse_channel,
    parse_schema,
    read_layout,
)
from uavtool.recording.schemas import (
    JSON_ENCODING,
    MAVLINK_ENCODING,
    PROTOBUF_ENCODING,
)
from uavtool.recording.values import Direction, Entry, JsonDocument, MavlinkFrame, Value

_MSG = struct.Struct("<HIQQ")
_REC = struct.Struct("<BQ")


@dataclass(frozen=True, slots=True)
class Message:
    """One undecoded message: its channel, schema (None if schemaless) and bytes."""

    channel: Channel
    schema: Schema | None
    sequence: int
    log_time_ns: int
    publish_time_ns: int
    data: bytes


class RecordingReader:
    """Reads an MCAP recording; a truncated one up to its last whole record, without raising.

    Raises `NotMcapError` (missing, empty, not MCAP) on open.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        try:
            with self.path.open("rb") as f:
                size = f.seek(0, 2)
                self._map: mmap.mmap | None = (
                    mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) if size else None
                )
        except OSError as exc:
            raise NotMcapError(path, f"cannot open: {exc.strerror}") from exc
        self._buf: Any = self._map if self._map is not None else b""
        try:
            self._layout: Layout = read_layout(self._buf)
        except NotMcap as exc:
            self.close()
            raise NotMcapError(path, str(exc)) from exc

    def __enter__(self) -> RecordingReader:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        if self._map is not None:
            self._map.close()
            self._map = None
            self._buf = b""

    # --- what the file holds -----------------------------------------------------------------

    @property
    def health(self) -> Health:
        return self._layout.health

    @property
    def library(self) -> str:
        return self._layout.library

    @property
    def channels(self) -> dict[int, Channel]:
        return dict(self._layout.channels)

    @property
    def schemas(self) -> dict[int, Schema]:
        return dict(self._layout.schemas)

    @property
    def metadata(self) -> list[tuple[str, dict[str, str]]]:
        """Metadata records in file order as ``(name, record)``."""
        return list(self._layout.metadata)

    @property
    def message_counts(self) -> dict[int, int]:
        """Readable messages per channel id."""
        return dict(self._layout.counts)

    @property
    def time_range_ns(self) -> tuple[int, int]:
        """First and last log time of the readable messages (0, 0 if none)."""
        return self._layout.start_ns, self._layout.end_ns

    def topics(self) -> list[str]:
        """The distinct topics of the readable channels, sorted."""
        return sorted({c.topic for c in self._layout.channels.values()})

    # --- messages ----------------------------------------------------------------------------

    def messages(
        self,
        topics: Iterable[str] | None = None,
        *,
        start_ns: int | None = None,
        end_ns: int | None = None,
    ) -> Iterator[Message]:
        """Messages of ``topics`` (all if None) with ``start_ns <= log_time < end_ns``, in file
        order. Raises `TopicNotFoundError` if a named topic is not in the file."""
        wanted: set[int] | None = None
        if topics is not None:
            wanted = set()
            present = self.topics()
            for topic in topics:
                ids = {c.id for c in self._layout.channels.values() if c.topic == topic}
                if not ids:
                    raise TopicNotFoundError(self.path, topic, present)
                wanted |= ids
        lo = 0 if start_ns is None else start_ns
        hi = 1 << 64 if end_ns is None else end_ns
        return self._iter(wanted, lo, hi)

    def _iter(self, wanted: set[int] | None, lo: int, hi: int) -> Iterator[Message]:
        for block in self._layout.blocks:
            if (
                wanted is not None
                and block.channel_ids is not None
                and not block.channel_ids & wanted
            ):
                continue
            if block.end_ns < lo or block.start_ns >= hi:
                continue
            records, start, end = self._records(block)
            yield from self._block_messages(records, start, end, wanted=wanted, lo=lo, hi=hi)

    def _records(self, block: Block) -> tuple[Any, int, int]:
        if block.data is not None:
            return block.data, 0, len(block.data)
        buf = self._buf
        if not block.chunked:
            return buf, block.offset, block.offset + block.length
        op, n = _REC.unpack_from(buf, block.offset)
        if op != Op.CHUNK:
            raise RecordingError(self.path, f"byte {block.offset}: the index points at no chunk")
        s = block.offset + 9
        compression, rs, rn, usize, _crc = chunk_payload(buf, s, s + n)
        try:
            data = decompress(compression, buf[rs : rs + rn], usize)
        except Exception as exc:
            raise RecordingError(
                self.path, f"byte {block.offset}: unreadable chunk ({exc})"
            ) from exc
        return data, 0, len(data)

    def _block_messages(
        self, buf: Any, start: int, end: int, *, wanted: set[int] | None, lo: int, hi: int
    ) -> Iterator[Message]:
        channels, schemas = self._layout.channels, self._layout.schemas
        unpack_msg = _MSG.unpack_from
        for op, s, e in iter_records(buf, start, end):
            if op == Op.MESSAGE:
                cid, seq, log_t, pub_t = unpack_msg(buf, s)
                if (wanted is None or cid in wanted) and lo <= log_t < hi:
                    channel = channels.get(cid)
                    if channel is None:
                        raise RecordingError(self.path, f"message on unknown channel id {cid}")
                    schema = schemas.get(channel.schema_id)
                    yield Message(channel, schema, seq, log_t, pub_t, bytes(buf[s + 22 : e]))
            elif op == Op.SCHEMA:  # files without a summary define these inside chunks
                schema = parse_schema(buf, s)
                schemas.setdefault(schema.id, schema)
            elif op == Op.CHANNEL:
                channel = parse_channel(buf, s)
                channels.setdefault(channel.id, channel)

    def entries(
        self,
        topics: Iterable[str] | None = None,
        *,
        start_ns: int | None = None,
        end_ns: int | None = None,
    ) -> Iterator[Entry]:
        """Like `messages`, decoded to our value types (see `decode`)."""
        for message in self.messages(topics, start_ns=start_ns, end_ns=end_ns):
            yield Entry(
                message.channel.topic,
                message.log_time_ns,
                message.publish_time_ns,
                message.sequence,
                self.decode(message),
            )

    def decode(self, message: Message) -> Value:
        """The value a message carries; `UnknownSchemaError` if we do not know its schema."""
        channel, schema = message.channel, message.schema
        encoding = channel.message_encoding
        if encoding == MAVLINK_ENCODING:
            try:
                direction = Direction(channel.metadata.get("direction"))
            except ValueError:
                raise UnknownSchemaError(
                    self.path, f"topic {channel.topic!r}: MAVLink channel without a direction"
                ) from None
            return MavlinkFrame(direction, message.data)
        if encoding == JSON_ENCODING:
            try:
                payload = json.loads(message.data)
            except ValueError as exc:
                raise RecordingError(
                    self.path, f"topic {channel.topic!r} #{message.sequence}: invalid JSON ({exc})"
                ) from None
            if not isinstance(payload, dict):
                raise RecordingError(self.path, f"topic {channel.topic!r}: JSON is not an object")
            return JsonDocument(schema.name if schema else "", payload)
        name = schema.name if schema else ""
        if encoding == PROTOBUF_ENCODING and name in foxglove.SCHEMA_NAMES:
            try:
                return foxglove.decode(name, message.data)
            except Exception as exc:  # protobuf's DecodeError and friends
                raise RecordingError(
                    self.path, f"topic {channel.topic!r} #{message.sequence}: bad {name} ({exc})"
                ) from None
        raise UnknownSchemaError(
            self.path,
            f"topic {channel.topic!r}: cannot decode {encoding!r} messages of schema {name!r}",
        )
