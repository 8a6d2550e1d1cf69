"""MCAP records at the byte level: opcodes, fields, decompression.

Every parser takes the end of the record it reads and raises `struct.error` rather than read
past it: a flipped length byte in a record without a CRC (metadata) must not turn the next
records into strings, and must not escape as a traceback (callers turn it into damage).
"""

from __future__ import annotations

import mmap
import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from enum import IntEnum

import lz4.frame  # type: ignore[import-untyped]
import zstandard

MAGIC = b"\x89MCAP0\r\n"
Buf = bytes | mmap.mmap  # a whole file, mapped or read
_REC = struct.Struct("<BQ")
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_CHUNK = struct.Struct("<QQQI")


class Op(IntEnum):
    HEADER = 0x01
    FOOTER = 0x02
    SCHEMA = 0x03
    CHANNEL = 0x04
    MESSAGE = 0x05
    CHUNK = 0x06
    MESSAGE_INDEX = 0x07
    CHUNK_INDEX = 0x08
    ATTACHMENT = 0x09
    ATTACHMENT_INDEX = 0x0A
    STATISTICS = 0x0B
    METADATA = 0x0C
    METADATA_INDEX = 0x0D
    SUMMARY_OFFSET = 0x0E
    DATA_END = 0x0F


def op_name(op: int) -> str:
    try:
        return Op(op).name.lower().replace("_", " ")
    except ValueError:
        return f"opcode 0x{op:02x}"


@dataclass(frozen=True, slots=True)
class Schema:
    id: int
    name: str
    encoding: str
    data: bytes


@dataclass(frozen=True, slots=True)
class Channel:
    id: int
    topic: str
    message_encoding: str
    schema_id: int
    metadata: Mapping[str, str]


class NotMcap(Exception):  # noqa: N818 - internal signal, turned into NotMcapError by the reader
    """The bytes are not an MCAP file (the message says why)."""


def read_str(buf: Buf, off: int, end: int) -> tuple[str, int]:
    """A length-prefixed UTF-8 string at ``off`` that must end by ``end``."""
    if off + 4 > end:
        raise struct.error("string runs past its record")
    (n,) = _U32.unpack_from(buf, off)
    stop = off + 4 + n
    if stop > end:
        raise struct.error("string runs past its record")
    return bytes(buf[off + 4 : stop]).decode("utf-8", "replace"), stop


def read_map(buf: Buf, off: int, end: int) -> tuple[dict[str, str], int]:
    """A string-to-string map at ``off`` that must end by ``end``."""
    if off + 4 > end:
        raise struct.error("map runs past its record")
    (n,) = _U32.unpack_from(buf, off)
    off += 4
    stop = off + n
    if stop > end:
        raise struct.error("map runs past its record")
    out: dict[str, str] = {}
    while off < stop:
        key, off = read_str(buf, off, stop)
        out[key], off = read_str(buf, off, stop)
    return out, stop


def parse_schema(buf: Buf, off: int, end: int) -> Schema:
    (sid,) = _U16.unpack_from(buf, off)
    name, off = read_str(buf, off + 2, end)
    encoding, off = read_str(buf, off, end)
    if off + 4 > end:
        raise struct.error("schema data runs past its record")
    (n,) = _U32.unpack_from(buf, off)
    if off + 4 + n > end:
        raise struct.error("schema data runs past its record")
    return Schema(sid, name, encoding, bytes(buf[off + 4 : off + 4 + n]))


def parse_channel(buf: Buf, off: int, end: int) -> Channel:
    if off + 4 > end:
        raise struct.error("channel record too short")
    cid, sid = struct.unpack_from("<HH", buf, off)
    topic, off = read_str(buf, off + 4, end)
    encoding, off = read_str(buf, off, end)
    meta, _ = read_map(buf, off, end)
    return Channel(cid, topic, encoding, sid, meta)


def parse_metadata(buf: Buf, off: int, end: int) -> tuple[str, dict[str, str]]:
    name, off = read_str(buf, off, end)
    record, _ = read_map(buf, off, end)
    return name, record


def decompress(compression: str, data: bytes, size: int) -> bytes:
    if compression == "zstd":
        return bytes(zstandard.ZstdDecompressor().decompress(data, max_output_size=size))
    if compression == "lz4":
        return bytes(lz4.frame.decompress(data))
    if compression == "":
        return bytes(data)
    raise NotMcap(f"unsupported chunk compression {compression!r}")


def decompress_prefix(compression: str, data: bytes) -> bytes:
    """As much of a cut compressed chunk as decodes (whole compression blocks)."""
    try:
        if compression == "zstd":
            return bytes(zstandard.ZstdDecompressor().decompressobj().decompress(data))
        if compression == "lz4":
            return bytes(lz4.frame.LZ4FrameDecompressor().decompress(data))
    except (zstandard.ZstdError, RuntimeError):
        return b""
    return bytes(data) if compression == "" else b""


def chunk_payload(buf: Buf, off: int, end: int) -> tuple[str, int, int, int, int]:
    """``(compression, records_start, records_len, uncompressed_size, crc)`` of a chunk record
    whose content starts at ``off`` and ends at ``end``."""
    _start, _end, size, crc = _CHUNK.unpack_from(buf, off)
    compression, off = read_str(buf, off + _CHUNK.size, end)
    (n,) = _U64.unpack_from(buf, off)
    return compression, off + 8, min(n, end - off - 8), size, crc


def iter_records(buf: Buf, off: int, end: int) -> Iterator[tuple[int, int, int]]:
    """``(opcode, content_start, content_end)`` of each whole record in ``buf[off:end]``;
    stops at the first record that runs past ``end`` (see `chunks.check_records` for data
    that must be whole)."""
    while off + 9 <= end:
        op, n = _REC.unpack_from(buf, off)
        start = off + 9
        off = start + n
        if off > end:
            return
        yield op, start, off
