"""`RecordingReader`: iterate a recording by topic and time range, whole or truncated.

Messages come in file order, which is the order they were written: for replay that is the
order the mission consumed its observations. `entries` decodes them to our value types.
"""

from __future__ import annotations

import json
import mmap
import struct
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from uavtool.recording import foxglove, rawframe
from uavtool.recording.chunks import Block, ChunkDamaged, Damage, chunk_damage, read_chunk
from uavtool.recording.errors import (
    CorruptRecordingError,
    NotMcapError,
    RecordingError,
    TopicNotFoundError,
    UnknownSchemaError,
)
from uavtool.recording.files import NotRegularFileError, open_input
from uavtool.recording.layout import Health, Layout, read_layout
from uavtool.recording.records import (
    Channel,
    NotMcap,
    Op,
    Schema,
    parse_channel,
    parse_schema,
)
from uavtool.recording.schemas import (
    JSON_ENCODING,
    MAVLINK_ENCODING,
    PROTOBUF_ENCODING,
)
from uavtool.recording.values import Direction, Entry, JsonDocument, MavlinkFrame, Value

_MSG = struct.Struct("<HIQQ")
_CID = struct.Struct("<H")  # a message's channel id
_REC = struct.Struct("<BQ")  # a record's opcode and length


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

    Every chunk is checked when it is read (see `chunks.read_chunk`): a chunk that fails
    raises `CorruptRecordingError` naming where it is, its topics, log times and the messages
    lost, and so does any read of all messages that yields fewer than the file's statistics
    promise. With ``skip_damaged`` such chunks are skipped instead and listed in `damage`
    (for recovery). Raises `NotMcapError` (missing, empty, not MCAP, not a regular file) on
    open.
    """

    def __init__(self, path: str | Path, *, skip_damaged: bool = False) -> None:
        self.path = Path(path)
        self._skip_damaged = skip_damaged
        self._found: list[Damage] = []  # damage found while reading
        self._checked: set[int] = set()  # offsets of chunks read and found good
        try:
            with open_input(self.path) as f:
                size = f.seek(0, 2)
                self._map: mmap.mmap | None = (
                    mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) if size else None
                )
        except NotRegularFileError as exc:
            raise NotMcapError(path, str(exc).removeprefix(f"{path}: ")) from None
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
    def summary_problem(self) -> str:
        """Why the file's summary was not used and the file was scanned instead ("" if it
        was used, or there is none)."""
        return self._layout.summary_problem

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
        """Metadata records in file order as ``(name, record)``; damaged ones are left out
        (see `damage`)."""
        return list(self._layout.metadata)

    @property
    def message_counts(self) -> dict[int, int]:
        """Messages per channel id: the summary's statistics for a whole file, what the scan
        could read for any other."""
        return dict(self._layout.counts)

    @property
    def time_range_ns(self) -> tuple[int, int]:
        """First and last log time of the readable messages (0, 0 if none)."""
        return self._layout.start_ns, self._layout.end_ns

    @property
    def damage(self) -> list[Damage]:
        """What could not be read so far: found while finding the layout, while reading, or
        by `verify`."""
        return [*self._layout.damage, *self._found]

    def topics(self) -> list[str]:
        """The distinct topics of the readable channels, sorted."""
        return sorted({c.topic for c in self._layout.channels.values()})

    def verify(self) -> list[Damage]:
        """Read and check every chunk not read yet (and the data-section CRC when the file
        has one); returns all the damage known. Never raises for damage."""
        layout = self._layout
        if layout.health.indexed:  # a scan has checked every chunk already
            for block in layout.blocks:
                if block.chunked and block.data is None and block.offset not in self._checked:
                    self._read_block(block, raise_damage=False)
        if not self.damage and not self.data_section_intact():
            self._found.append(
                Damage(
                    "data section",
                    8,
                    layout.data_end - 8,
                    "CRC mismatch outside every chunk (a metadata or other record)",
                )
            )
        return self.damage

    def data_section_intact(self) -> bool:
        """Whether the data section matches its CRC (True when the file has none): a cheap
        check of the records outside the chunks, which carry no CRC of their own."""
        layout = self._layout
        return not layout.data_crc or self._crc32(layout.data_end) == layout.data_crc

    def _crc32(self, end: int) -> int:
        with memoryview(self._buf) as view, view[:end] as data:  # no copy of the file
            return zlib.crc32(data)

    def require_intact(self) -> None:
        """`verify`, and raise `CorruptRecordingError` for the first damage found."""
        damage = self.verify()
        if damage:
            raise self._corrupt(damage[0])

    def require_decodable(self) -> None:
        """Decode every message of a schema we know; `RecordingError` names the first that
        does not decode (content crafted or damaged before the file's checksums were made)."""
        for message in self.messages():
            try:
                self.decode(message)
            except UnknownSchemaError:
                continue

    def require_metadata(self, names: Iterable[str]) -> None:
        """Raise `CorruptRecordingError` if a metadata record named in ``names`` (or one whose
        name is unknown) is damaged."""
        wanted = set(names)
        for d in self._layout.damage:
            if d.kind == "metadata" and (not d.name or d.name in wanted):
                what = f"metadata record {d.name!r}" if d.name else "a metadata record"
                raise CorruptRecordingError(
                    self.path, f"byte {d.offset}: {what} is damaged ({d.problem})"
                )
        # A metadata record has no CRC of its own: the data section's (when the file has one)
        # is what says its values are the ones written.
        crc = self._layout.data_crc
        if crc and self._crc32(self._layout.data_end) != crc:
            damage = self.verify()
            raise (
                self._corrupt(damage[0])
                if damage
                else CorruptRecordingError(self.path, "the data section fails its CRC")
            )

    def describe(self, damage: Damage) -> str:
        """One line: where the damage is, what it held and what was lost."""
        if damage.kind != "chunk":
            name = f" {damage.name!r}" if damage.name else ""
            return f"byte {damage.offset}: damaged {damage.kind} record{name} ({damage.problem})"
        t0 = self._layout.start_ns
        when = (
            f", log time {(damage.start_ns - t0) / 1e9:.3f}–{(damage.end_ns - t0) / 1e9:.3f} s"
            if damage.end_ns >= damage.start_ns >= t0 > 0
            else ""
        )
        lost = (
            f"{damage.messages_lost} messages lost on {_listing(self._topics(damage.lost))}"
            if damage.lost
            else "its messages are lost (how many is unknown)"
        )
        return (
            f"byte {damage.offset}: corrupt chunk of {damage.length} bytes ({damage.problem})"
            f"{when}: {lost}"
        )

    def _topics(self, channel_ids: Iterable[int]) -> list[str]:
        channels = self._layout.channels
        return sorted({channels[c].topic if c in channels else f"channel {c}" for c in channel_ids})

    # --- messages ----------------------------------------------------------------------------

    def messages(
        self,
        topics: Iterable[str] | None = None,
        *,
        start_ns: int | None = None,
        end_ns: int | None = None,
    ) -> Iterator[Message]:
        """Messages of ``topics`` (all if None) with ``start_ns <= log_time < end_ns``, in file
        order. Raises `TopicNotFoundError` if a named topic is not in the file, and
        `CorruptRecordingError` (see the class) when they cannot all be read."""
        wanted: set[int] | None = None
        if topics is not None:
            wanted = set()
            present = self.topics()
            for topic in topics:
                ids = {c.id for c in self._layout.channels.values() if c.topic == topic}
                if not ids:
                    raise TopicNotFoundError(self.path, topic, present)
                wanted |= ids
        if not self._skip_damaged:
            for d in self._layout.damage:  # chunks a scan found bad: not in the blocks
                if d.kind == "chunk" and (
                    not d.lost or wanted is None or wanted.intersection(d.lost)
                ):
                    raise self._corrupt(d)
        lo = 0 if start_ns is None else start_ns
        hi = 1 << 64 if end_ns is None else end_ns
        return self._iter(wanted, lo, hi)

    def _corrupt(self, damage: Damage) -> CorruptRecordingError:
        return CorruptRecordingError(
            self.path,
            f"{self.describe(damage)}; `uavtool info --recover {self.path} -o fixed.mcap` "
            "keeps every good chunk",
        )

    def _iter(self, wanted: set[int] | None, lo: int, hi: int) -> Iterator[Message]:
        count = 0
        for block in self._layout.blocks:
            if (
                wanted is not None
                and block.channel_ids is not None
                and not block.channel_ids & wanted
            ):
                continue
            if block.end_ns < lo or block.start_ns >= hi:
                continue
            records = self._read_block(block, raise_damage=not self._skip_damaged)
            for message in self._block_messages(records, wanted=wanted, lo=lo, hi=hi):
                count += 1
                yield message
        if lo == 0 and hi == 1 << 64 and not self._skip_damaged:
            counts = self._layout.counts
            expected = sum(n for c, n in counts.items() if wanted is None or c in wanted)
            if count < expected:
                raise CorruptRecordingError(
                    self.path,
                    f"read {count} of the {expected} messages its summary counts on "
                    f"{_listing(self._topics(wanted or counts))}: the file holds less than "
                    "it says",
                )

    def _read_block(self, block: Block, *, raise_damage: bool) -> Any:
        """The records of ``block`` (a checked chunk's, a cut chunk's rescued prefix, or the
        file for a message outside chunks); b"" for a damaged chunk unless ``raise_damage``."""
        if block.data is not None:
            return block.data
        if not block.chunked:
            return self._buf[block.offset : block.offset + block.length]
        try:
            data = read_chunk(self._buf, block)
        except ChunkDamaged as exc:
            damage = chunk_damage(self._buf, block, str(exc))
            if all(d.offset != block.offset for d in self._found):
                self._found.append(damage)
            if raise_damage:
                raise self._corrupt(damage) from None
            return b""
        self._checked.add(block.offset)
        return data

    def _block_messages(
        self, buf: Any, *, wanted: set[int] | None, lo: int, hi: int
    ) -> Iterator[Message]:
        channels, schemas = self._layout.channels, self._layout.schemas
        # `iter_records` inlined, and a message's channel read before the rest of it: most
        # records are skipped here (replay wants ~2.4k of a paper flight's 32.5k messages)
        unpack_rec, unpack_cid, unpack_msg = _REC.unpack_from, _CID.unpack_from, _MSG.unpack_from
        message, off, end = int(Op.MESSAGE), 0, len(buf)
        while off + 9 <= end:
            op, n = unpack_rec(buf, off)
            s = off + 9
            e = off = s + n
            if e > end:
                return
            if op == message:
                if wanted is not None and unpack_cid(buf, s)[0] not in wanted:
                    continue
                cid, seq, log_t, pub_t = unpack_msg(buf, s)
                if lo <= log_t < hi:
                    channel = channels.get(cid)
                    if channel is None:
                        if self._skip_damaged:  # its channel was defined in a damaged chunk
                            continue
                        raise RecordingError(self.path, f"message on unknown channel id {cid}")
                    schema = schemas.get(channel.schema_id)
                    yield Message(channel, schema, seq, log_t, pub_t, bytes(buf[s + 22 : e]))
            elif op == Op.SCHEMA:  # files without a summary define these inside chunks
                schema = parse_schema(buf, s, e)
                schemas.setdefault(schema.id, schema)
            elif op == Op.CHANNEL:
                channel = parse_channel(buf, s, e)
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
        if encoding == PROTOBUF_ENCODING and schema and schema.name == rawframe.SCHEMA_NAME:
            try:
                return MavlinkFrame(*rawframe.decode(message.data))
            except ValueError as exc:
                raise RecordingError(
                    self.path, f"topic {channel.topic!r} #{message.sequence}: {exc}"
                ) from None
        if encoding == MAVLINK_ENCODING:  # recordings written before uavtool.MavlinkFrame
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
            except ValueError as exc:  # not JSON, not UTF-8
                raise RecordingError(
                    self.path, f"topic {channel.topic!r} #{message.sequence}: invalid JSON ({exc})"
                ) from None
            except RecursionError:
                raise RecordingError(
                    self.path, f"topic {channel.topic!r} #{message.sequence}: JSON nested too deep"
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


def _listing(topics: list[str], most: int = 4) -> str:
    """``/a, /b, /c and 5 more topics``: short enough for a one-line error."""
    if len(topics) <= most:
        return ", ".join(topics)
    return f"{', '.join(topics[:most])} and {len(topics) - most} more topics"
