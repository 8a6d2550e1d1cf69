"""Finds what an MCAP file holds, whole or cut: schemas, channels, metadata and data blocks.

A whole file (footer + magic at the end, summary CRC good) is read from its summary without
touching the data. Anything else — a crash mid-write, a cut anywhere, a file without a
summary — is scanned record by record from the start up to the last whole record; a chunk
cut in the middle still gives up the messages in its complete compression blocks. The stock
`mcap` readers fail on such files; this one never raises past the cut.
"""

from __future__ import annotations

import mmap
import struct
import zlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from enum import IntEnum

import lz4.frame  # type: ignore[import-untyped]
import zstandard

MAGIC = b"\x89MCAP0\r\n"
Buf = bytes | mmap.mmap  # a whole file, mapped or read
_REC = struct.Struct("<BQ")
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_MSG = struct.Struct("<HIQQ")
_CHUNK = struct.Struct("<QQQI")
_FOOTER = struct.Struct("<BQQQI")
_FOOTER_SIZE = _FOOTER.size  # opcode + length + 20 bytes


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


@dataclass(slots=True)
class Block:
    """A run of records in the data section: a chunk, or one message outside any chunk.

    ``channel_ids`` is None when unknown (then the block is always read). ``data`` holds the
    recovered prefix of a cut chunk.
    """

    offset: int
    length: int
    start_ns: int
    end_ns: int
    chunked: bool
    channel_ids: frozenset[int] | None
    data: bytes | None = None


@dataclass(frozen=True, slots=True)
class Health:
    """How whole a file is. ``readable_bytes`` = where the last whole record ends."""

    whole: bool
    indexed: bool
    size_bytes: int
    readable_bytes: int
    problem: str = ""
    partial_chunk: bool = False


@dataclass(slots=True)
class Layout:
    profile: str = ""
    library: str = ""
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    metadata: list[tuple[str, dict[str, str]]] = field(default_factory=list)
    blocks: list[Block] = field(default_factory=list)
    counts: dict[int, int] = field(default_factory=dict)  # channel id -> messages
    start_ns: int = 0
    end_ns: int = 0
    health: Health = Health(False, False, 0, 0)


class NotMcap(Exception):  # noqa: N818 - internal signal, turned into NotMcapError by the reader
    """The bytes are not an MCAP file (the message says why)."""


# --- field parsing --------------------------------------------------------------------------


def _str(buf: Buf, off: int) -> tuple[str, int]:
    (n,) = _U32.unpack_from(buf, off)
    end = off + 4 + n
    if end > len(buf):
        raise struct.error("string runs past its record")
    return bytes(buf[off + 4 : end]).decode("utf-8", "replace"), end


def _map(buf: Buf, off: int) -> tuple[dict[str, str], int]:
    (n,) = _U32.unpack_from(buf, off)
    off += 4
    end = off + n
    out: dict[str, str] = {}
    while off < end:
        key, off = _str(buf, off)
        out[key], off = _str(buf, off)
    return out, end


def parse_schema(buf: Buf, off: int) -> Schema:
    (sid,) = _U16.unpack_from(buf, off)
    name, off = _str(buf, off + 2)
    encoding, off = _str(buf, off)
    (n,) = _U32.unpack_from(buf, off)
    return Schema(sid, name, encoding, bytes(buf[off + 4 : off + 4 + n]))


def parse_channel(buf: Buf, off: int) -> Channel:
    cid, sid = struct.unpack_from("<HH", buf, off)
    topic, off = _str(buf, off + 4)
    encoding, off = _str(buf, off)
    meta, _ = _map(buf, off)
    return Channel(cid, topic, encoding, sid, meta)


def decompress(compression: str, data: bytes, size: int) -> bytes:
    if compression == "zstd":
        return bytes(zstandard.ZstdDecompressor().decompress(data, max_output_size=size))
    if compression == "lz4":
        return bytes(lz4.frame.decompress(data))
    if compression == "":
        return bytes(data)
    raise NotMcap(f"unsupported chunk compression {compression!r}")


def _decompress_prefix(compression: str, data: bytes) -> bytes:
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
    whose content starts at ``off``."""
    _start, _end, size, crc = _CHUNK.unpack_from(buf, off)
    compression, off = _str(buf, off + _CHUNK.size)
    (n,) = _U64.unpack_from(buf, off)
    return compression, off + 8, min(n, end - off - 8), size, crc


def iter_records(buf: Buf, off: int, end: int) -> Iterator[tuple[int, int, int]]:
    """``(opcode, content_start, content_end)`` of each whole record in ``buf[off:end]``."""
    while off + 9 <= end:
        op, n = _REC.unpack_from(buf, off)
        start = off + 9
        off = start + n
        if off > end:
            return
        yield op, start, off


# --- whole files: the summary ---------------------------------------------------------------


def _read_summary(buf: Buf, layout: Layout) -> bool:
    """Fill ``layout`` from the summary; False if there is none or it does not check out."""
    size = len(buf)
    if size < 8 + _FOOTER_SIZE + 8 or bytes(buf[-8:]) != MAGIC:
        return False
    fpos = size - 8 - _FOOTER_SIZE
    op, n, summary_start, _offsets, crc = _FOOTER.unpack_from(buf, fpos)
    if op != Op.FOOTER or n != 20 or summary_start == 0 or not 8 < summary_start <= fpos:
        return False
    if (
        crc
        and zlib.crc32(buf[fpos : fpos + _FOOTER_SIZE - 4], zlib.crc32(buf[summary_start:fpos]))
        != crc
    ):
        return False
    stats_chunks, stats_channels = -1, -1
    chunk_blocks: list[Block] = []
    meta_offsets: list[tuple[int, int]] = []
    for op, s, _e in iter_records(buf, summary_start, fpos):
        if op == Op.SCHEMA:
            schema = parse_schema(buf, s)
            layout.schemas[schema.id] = schema
        elif op == Op.CHANNEL:
            channel = parse_channel(buf, s)
            layout.channels[channel.id] = channel
        elif op == Op.STATISTICS:
            (layout.start_ns, layout.end_ns) = struct.unpack_from("<QQ", buf, s + 26)
            (stats_channels,) = _U32.unpack_from(buf, s + 10)
            (stats_chunks,) = _U32.unpack_from(buf, s + 22)
            (n_counts,) = _U32.unpack_from(buf, s + 42)
            for k in range(s + 46, s + 46 + n_counts, 10):
                cid, count = struct.unpack_from("<HQ", buf, k)
                layout.counts[cid] = count
        elif op == Op.CHUNK_INDEX:
            start_ns, end_ns, offset, length = struct.unpack_from("<QQQQ", buf, s)
            (n_idx,) = _U32.unpack_from(buf, s + 32)
            ids = frozenset(_U16.unpack_from(buf, k)[0] for k in range(s + 36, s + 36 + n_idx, 10))
            chunk_blocks.append(Block(offset, length, start_ns, end_ns, True, ids or None))
        elif op == Op.METADATA_INDEX:
            meta_offsets.append(struct.unpack_from("<QQ", buf, s))
    if stats_chunks != len(chunk_blocks) or (not layout.counts and stats_chunks):
        return False  # no statistics, or messages outside chunks: scan instead
    if sum(layout.counts.values()) and not chunk_blocks:
        return False
    if stats_channels != len(layout.channels):  # channels not repeated in the summary
        return False
    layout.blocks = sorted(chunk_blocks, key=lambda b: b.offset)
    for offset, _length in meta_offsets:
        name, off = _str(buf, offset + 9)
        layout.metadata.append((name, _map(buf, off)[0]))
    _read_header(buf, layout)
    layout.health = Health(True, True, size, size)
    return True


def _read_header(buf: Buf, layout: Layout) -> None:
    for op, s, _e in iter_records(buf, 8, min(len(buf), 1 << 16)):
        if op == Op.HEADER:
            layout.profile, off = _str(buf, s)
            layout.library, _ = _str(buf, off)
        break


# --- cut or summary-less files: a linear scan -----------------------------------------------


def _scan_chunk(
    layout: Layout, records: bytes, offset: int, length: int, data: bytes | None
) -> Block:
    ids: set[int] = set()
    start_ns, end_ns = 1 << 64, 0
    for op, s, _e in iter_records(records, 0, len(records)):
        if op == Op.MESSAGE:
            cid, _seq, t = struct.unpack_from("<HIQ", records, s)
            ids.add(cid)
            layout.counts[cid] = layout.counts.get(cid, 0) + 1
            start_ns, end_ns = min(start_ns, t), max(end_ns, t)
        elif op == Op.SCHEMA:
            schema = parse_schema(records, s)
            layout.schemas[schema.id] = schema
        elif op == Op.CHANNEL:
            channel = parse_channel(records, s)
            layout.channels[channel.id] = channel
    return Block(offset, length, start_ns if ids else 0, end_ns, True, frozenset(ids), data)


def _rescue_chunk(buf: Buf, layout: Layout, pos: int, s: int) -> bool:
    """Keep the whole messages at the start of a chunk cut by the end of the file."""
    try:
        comp, rs, rn, _usize, _crc = chunk_payload(buf, s, len(buf))
    except struct.error:  # cut inside the chunk's own header fields
        return False
    data = _decompress_prefix(comp, buf[rs : rs + rn])
    if not data:
        return False
    block = _scan_chunk(layout, data, pos, len(buf) - pos, data)
    if not block.channel_ids:
        return False
    layout.blocks.append(block)
    return True


def _scan(buf: Buf, layout: Layout) -> None:
    size = len(buf)
    pos, problem, partial = 8, "", False
    while True:
        if pos + 9 > size:
            problem = f"cut at byte {size}: no footer" if pos == size else f"cut at byte {size}"
            break
        op, n = _REC.unpack_from(buf, pos)
        s, e = pos + 9, pos + 9 + n
        if op == 0:
            problem = f"damaged at byte {pos}: invalid record"
            break
        try:
            if e > size:
                problem = (
                    f"cut at byte {size} inside a {_op_name(op)} record starting at byte {pos}"
                )
                if op == Op.CHUNK:
                    partial = _rescue_chunk(buf, layout, pos, s)
                break
            if op == Op.HEADER:
                layout.profile, off = _str(buf, s)
                layout.library, _ = _str(buf, off)
            elif op == Op.SCHEMA:
                schema = parse_schema(buf, s)
                layout.schemas[schema.id] = schema
            elif op == Op.CHANNEL:
                channel = parse_channel(buf, s)
                layout.channels[channel.id] = channel
            elif op == Op.MESSAGE:
                cid, _seq, t = struct.unpack_from("<HIQ", buf, s)
                layout.counts[cid] = layout.counts.get(cid, 0) + 1
                layout.blocks.append(Block(pos, e - pos, t, t, False, frozenset((cid,))))
            elif op == Op.CHUNK:
                comp, rs, rn, usize, crc = chunk_payload(buf, s, e)
                records = decompress(comp, buf[rs : rs + rn], usize)
                if crc and zlib.crc32(records) != crc:
                    problem = f"damaged at byte {pos}: chunk CRC mismatch"
                    break
                layout.blocks.append(_scan_chunk(layout, records, pos, e - pos, None))
            elif op == Op.METADATA:
                name, off = _str(buf, s)
                layout.metadata.append((name, _map(buf, off)[0]))
            elif op in (Op.DATA_END, Op.FOOTER):
                break  # the data section is over; everything in it was readable
        except (struct.error, zstandard.ZstdError, RuntimeError, NotMcap) as exc:
            problem = f"damaged at byte {pos}: unreadable {_op_name(op)} record ({exc})"
            break
        pos = e
    readable = pos
    whole = not problem and bytes(buf[-8:]) == MAGIC
    if not whole and not problem:
        problem = f"cut at byte {size} in the summary (all data readable)"
    layout.health = Health(whole, False, size, readable, problem, partial)
    times = [(b.start_ns, b.end_ns) for b in layout.blocks if b.channel_ids]
    if times:
        layout.start_ns = min(t[0] for t in times)
        layout.end_ns = max(t[1] for t in times)


def _op_name(op: int) -> str:
    try:
        return Op(op).name.lower().replace("_", " ")
    except ValueError:
        return f"opcode 0x{op:02x}"


def read_layout(buf: Buf) -> Layout:
    """The layout of an MCAP file's bytes; raises `NotMcap` if they are not MCAP at all."""
    if not buf:
        raise NotMcap("empty file")
    head = bytes(buf[:8])
    if head != MAGIC[: len(head)]:
        raise NotMcap(f"not an MCAP file (starts with {head!r})")
    layout = Layout()
    if len(buf) < 8:
        layout.health = Health(
            False, False, len(buf), 0, f"cut at byte {len(buf)} inside the magic"
        )
        return layout
    if not _read_summary(buf, layout):
        layout = Layout()
        _scan(buf, layout)
    return layout
