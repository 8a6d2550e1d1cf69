"""`McapEncoder`: writes MCAP records to a binary file, chunk by chunk.

It writes the very bytes mcap's own `Writer` writes with ``compression=ZSTD`` and
``enable_data_crcs=True``, every other option at its default (all indexes, statistics, schemas
and channels repeated in the summary, summary offsets, CRCs) when the same calls close chunks
at the same points — the tests check this byte for byte. The data section's CRC covers what
no chunk CRC does (the metadata records: the flight's parameters, scene and outcome), so a
reader can tell a flipped metadata byte from a whole file.

It exists for speed: mcap's `Writer` builds each message through a dataclass and a handful
of `struct.pack` calls (about three quarters of the writer's time on small JSON messages);
here a message is one `struct.pack` and two appends, and per-chunk statistics are taken from
the message index when the chunk closes.

Not thread-safe: `RecordingWriter` serializes calls. Every ``*_ns`` is an unsigned 64-bit
integer; out-of-range values raise `struct.error` before anything is written.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import BinaryIO

import zstandard

MAGIC = b"\x89MCAP0\r\n"
_HEADER, _FOOTER, _SCHEMA, _CHANNEL, _MESSAGE, _CHUNK, _MESSAGE_INDEX = 1, 2, 3, 4, 5, 6, 7
_CHUNK_INDEX, _ATTACHMENT_INDEX, _STATISTICS, _METADATA, _METADATA_INDEX = 8, 10, 11, 12, 13
_SUMMARY_OFFSET, _DATA_END = 14, 15

_REC = struct.Struct("<BQ")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_MSG = struct.Struct("<BQHIQQ")  # record head + channel, sequence, log time, publish time
_MSG_FIELDS = 22  # bytes of a Message record's fixed fields
_CHUNK_HEAD = struct.Struct("<BQQQQI")  # record head + start, end, uncompressed size and CRC
_ZSTD = _U32.pack(4) + b"zstd"
_CHUNK_FIXED = 8 + 8 + 8 + 4 + len(_ZSTD) + 8  # chunk fields around the compressed bytes
_MSG_INDEX_HEAD = struct.Struct("<BQHI")


def _str(text: str) -> bytes:
    data = text.encode()
    return _U32.pack(len(data)) + data


def _map(pairs: Mapping[str, str]) -> bytes:
    body = b"".join(_str(k) + _str(v) for k, v in pairs.items())
    return _U32.pack(len(body)) + body


def _record(opcode: int, body: bytes) -> bytes:
    return _REC.pack(opcode, len(body)) + body


@dataclass(frozen=True, slots=True)
class Chunk:
    """A chunk ended by `McapEncoder.take_chunk`: its records, uncompressed, and its message
    index (channel id -> [log time, offset in the chunk, log time, offset, ...])."""

    records: bytearray
    index: dict[int, list[int]]


class McapEncoder:
    """Writes an MCAP file to ``file`` (magic and header at once). Call `finish` to end it.

    Messages go into the open chunk, which only `close_chunk` (or `finish`) compresses and
    writes: when to close it is the caller's policy.
    """

    def __init__(self, file: BinaryIO, *, library: str, profile: str = "") -> None:
        self._file = file
        self._pos = 0  # bytes written so far = offset of the next record
        self._data_crc = 0  # CRC-32 of the data section written so far
        self._chunk = bytearray()  # records of the open chunk, uncompressed
        # channel id -> [log time, offset in chunk, log time, offset, ...] for the open chunk
        self._index: dict[int, list[int]] = {}
        self._schemas: list[bytes] = []  # records, repeated in the summary
        self._channels: list[bytes] = []
        self._chunk_indexes: list[bytes] = []
        self._metadata_indexes: list[bytes] = []
        self._counts: dict[int, int] = {}  # channel id -> messages, in order of first message
        self._message_count = 0
        self._start_ns: int | None = None
        self._end_ns = 0
        # mcap's Writer calls zstandard.compress(), which builds a level-3 context per chunk;
        # reusing one gives the same frames for a third less time on 64 KiB chunks
        self._zstd = zstandard.ZstdCompressor(level=3)
        self._write(MAGIC + _record(_HEADER, _str(profile) + _str(library)))

    def _write(self, data: bytes) -> None:
        self._file.write(data)
        self._pos += len(data)
        self._data_crc = zlib.crc32(data, self._data_crc)

    def add_metadata(self, name: str, pairs: Mapping[str, str]) -> None:
        """Write a metadata record (outside chunks) and hand it to the OS."""
        record = _record(_METADATA, _str(name) + _map(pairs))
        index = _U64.pack(self._pos) + _U64.pack(len(record)) + _str(name)
        self._metadata_indexes.append(_record(_METADATA_INDEX, index))
        self._write(record)
        self._file.flush()

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        """A new schema id (1, 2, …); the record goes into the open chunk."""
        schema_id = len(self._schemas) + 1
        body = struct.pack("<H", schema_id) + _str(name) + _str(encoding)
        record = _record(_SCHEMA, body + _U32.pack(len(data)) + data)
        self._schemas.append(record)
        self._chunk += record
        return schema_id

    def register_channel(
        self, topic: str, encoding: str, schema_id: int, metadata: Mapping[str, str]
    ) -> int:
        """A new channel id (1, 2, …); the record goes into the open chunk."""
        channel_id = len(self._channels) + 1
        body = struct.pack("<HH", channel_id, schema_id) + _str(topic) + _str(encoding)
        record = _record(_CHANNEL, body + _map(metadata))
        self._channels.append(record)
        self._chunk += record
        return channel_id

    def add_message(
        self, channel_id: int, sequence: int, log_time_ns: int, publish_time_ns: int, data: bytes
    ) -> int:
        """Append a message to the open chunk; returns the chunk's uncompressed size so far."""
        chunk = self._chunk
        offset = len(chunk)
        chunk += _MSG.pack(
            _MESSAGE, _MSG_FIELDS + len(data), channel_id, sequence, log_time_ns, publish_time_ns
        )
        chunk += data
        index = self._index.get(channel_id)
        if index is None:
            self._index[channel_id] = [log_time_ns, offset]
        else:
            index += (log_time_ns, offset)
        return len(chunk)

    def close_chunk(self) -> None:
        """Compress the open chunk, write it and its message indexes, flush the file. A chunk
        without messages stays open (its schema/channel records move on to the next one)."""
        chunk = self.take_chunk()
        if chunk is not None:
            self.write_chunk(chunk)
        else:
            self._file.flush()

    def take_chunk(self) -> Chunk | None:
        """End the open chunk and start the next, without writing it: `write_chunk` does,
        maybe on another thread, before anything written after it. None if it holds no
        message (its schema/channel records then stay for the next one)."""
        if not self._index:
            return None
        chunk = Chunk(self._chunk, self._index)
        self._chunk = bytearray()
        self._index = {}
        return chunk

    def write_chunk(self, chunk: Chunk) -> None:
        """Compress a chunk `take_chunk` ended, write it and its message indexes, flush the
        file. Chunks must be written in the order they were taken, and before any metadata
        or the summary that follows them."""
        records = chunk.records
        compressed = self._zstd.compress(records)
        start_ns = min(min(ix[0::2]) for ix in chunk.index.values())
        end_ns = max(max(ix[0::2]) for ix in chunk.index.values())
        length = _CHUNK_FIXED + len(compressed)
        head = _CHUNK_HEAD.pack(_CHUNK, length, start_ns, end_ns, len(records), zlib.crc32(records))
        parts = [head, _ZSTD, _U64.pack(len(compressed)), compressed]
        chunk_offset = self._pos
        index_pos = chunk_offset + _REC.size + length
        offsets = []
        for channel_id, index in chunk.index.items():
            n = len(index)
            parts.append(_MSG_INDEX_HEAD.pack(_MESSAGE_INDEX, 6 + 8 * n, channel_id, 8 * n))
            parts.append(struct.pack(f"<{n}Q", *index))
            offsets.append(struct.pack("<HQ", channel_id, index_pos))
            index_pos += _MSG_INDEX_HEAD.size + 8 * n
            self._counts[channel_id] = self._counts.get(channel_id, 0) + n // 2
            self._message_count += n // 2
        message_index_length = index_pos - (chunk_offset + _REC.size + length)
        self._chunk_indexes.append(
            _record(
                _CHUNK_INDEX,
                struct.pack("<QQQQ", start_ns, end_ns, chunk_offset, _REC.size + length)
                + _U32.pack(10 * len(offsets))
                + b"".join(offsets)
                + _U64.pack(message_index_length)
                + _ZSTD
                + _U64.pack(len(compressed))
                + _U64.pack(len(records)),
            )
        )
        if self._start_ns is None or start_ns < self._start_ns:
            self._start_ns = start_ns
        self._end_ns = max(self._end_ns, end_ns)
        self._write(b"".join(parts))
        self._file.flush()

    def finish(self) -> None:
        """Close the open chunk, then write the data end, the summary, the footer and the
        closing magic, and flush the file (it stays open)."""
        self.close_chunk()
        self._write(_record(_DATA_END, _U32.pack(self._data_crc)))
        summary_start = self._pos
        counts = b"".join(struct.pack("<HQ", c, n) for c, n in self._counts.items())
        statistics = struct.pack(
            "<QHIIIIQQ",
            self._message_count,
            len(self._schemas),
            len(self._channels),
            0,  # attachments
            len(self._metadata_indexes),
            len(self._chunk_indexes),
            self._start_ns or 0,
            self._end_ns,
        )
        groups = (
            (_SCHEMA, b"".join(self._schemas)),
            (_CHANNEL, b"".join(self._channels)),
            (_STATISTICS, _record(_STATISTICS, statistics + _U32.pack(len(counts)) + counts)),
            (_CHUNK_INDEX, b"".join(self._chunk_indexes)),
            (_ATTACHMENT_INDEX, b""),
            (_METADATA_INDEX, b"".join(self._metadata_indexes)),
        )
        summary = bytearray()
        offsets = []
        for opcode, group in groups:
            offset = struct.pack("<BQQ", opcode, summary_start + len(summary), len(group))
            offsets.append(_record(_SUMMARY_OFFSET, offset))
            summary += group
        offsets_start = summary_start + len(summary)
        summary += b"".join(offsets)
        footer = _REC.pack(_FOOTER, 20) + _U64.pack(summary_start) + _U64.pack(offsets_start)
        crc = zlib.crc32(footer, zlib.crc32(summary))
        self._write(bytes(summary) + footer + _U32.pack(crc) + MAGIC)
        self._file.flush()
