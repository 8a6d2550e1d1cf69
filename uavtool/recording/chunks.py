"""Reading one chunk strictly, and saying what is lost when it cannot be read.

A chunk carries a CRC of its uncompressed records; nothing else in the data section does
(metadata records have none, and our files, like mcap's default writer, leave the
data-section CRC at 0). So a chunk is trusted only when its record matches the index that
points at it, it decompresses to exactly its stated size, its CRC matches, and its records
fill it exactly. Anything less is `Damage`, never a shorter read.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field

import zstandard

from uavtool.recording.records import Buf, NotMcap, Op, chunk_payload, decompress

_REC = struct.Struct("<BQ")
_MSG_INDEX = struct.Struct("<HI")
_MSG_FIELDS = 22  # channel id, sequence, log time, publish time


@dataclass(slots=True)
class Block:
    """A run of records in the data section: a chunk, or one message outside any chunk.

    ``channel_ids`` is None when unknown (then the block is always read). ``data`` holds the
    recovered prefix of a cut chunk, or a chunk already read and checked by a scan.
    """

    offset: int
    length: int
    start_ns: int
    end_ns: int
    chunked: bool
    channel_ids: frozenset[int] | None
    data: bytes | None = None


@dataclass(frozen=True, slots=True)
class Damage:
    """A part of the data section that cannot be read: a chunk or a metadata record.

    ``lost`` maps channel id -> messages the file says were there (from the chunk's message
    index), empty when that is unknown too. ``name`` is a metadata record's name when the
    summary gives it.
    """

    kind: str  # "chunk" | "metadata"
    offset: int
    length: int
    problem: str
    start_ns: int = 0
    end_ns: int = 0
    lost: Mapping[int, int] = field(default_factory=dict)
    name: str = ""

    @property
    def messages_lost(self) -> int:
        return sum(self.lost.values())


class ChunkDamaged(Exception):  # noqa: N818 - internal signal, turned into Damage by callers
    """The chunk cannot be trusted (the message says why)."""


def read_chunk(buf: Buf, block: Block) -> bytes:
    """The uncompressed records of the chunk ``block`` points at, checked as the module
    docstring says. Raises `ChunkDamaged`."""
    end = block.offset + block.length
    if end > len(buf):
        raise ChunkDamaged("runs past the end of the file")
    try:
        op, n = _REC.unpack_from(buf, block.offset)
        if op != Op.CHUNK:
            raise ChunkDamaged(f"the index points at no chunk (opcode 0x{op:02x})")
        if block.offset + 9 + n != end:
            raise ChunkDamaged("its record length does not match the index")
        compression, rs, rn, size, crc = chunk_payload(buf, block.offset + 9, end)
        if rs + rn != end:
            raise ChunkDamaged("its compressed length does not match its record")
        data = decompress(compression, buf[rs : rs + rn], size)
    except (struct.error, zstandard.ZstdError, RuntimeError, NotMcap) as exc:
        raise ChunkDamaged(f"unreadable ({exc})") from None
    if len(data) != size:
        raise ChunkDamaged(f"decompresses to {len(data)} bytes, not {size}")
    if crc and zlib.crc32(data) != crc:
        raise ChunkDamaged("CRC mismatch")
    check_records(data)
    return data


def check_records(data: bytes) -> None:
    """Raise `ChunkDamaged` unless ``data`` is a run of whole records filling it exactly."""
    off, end = 0, len(data)
    while off < end:
        if off + 9 > end:
            raise ChunkDamaged(f"a record header is cut at byte {off} of the chunk")
        op, n = _REC.unpack_from(data, off)
        if off + 9 + n > end:
            raise ChunkDamaged(f"the record at byte {off} of the chunk runs past it")
        if op == Op.MESSAGE and n < _MSG_FIELDS:
            raise ChunkDamaged(f"the message at byte {off} of the chunk is too short")
        off += 9 + n


def index_counts(buf: Buf, block: Block) -> dict[int, int]:
    """Messages per channel id that the message index records right after a chunk list
    (empty if there are none or they are unreadable)."""
    counts: dict[int, int] = {}
    off = block.offset + block.length
    try:
        while off + 9 <= len(buf):
            op, n = _REC.unpack_from(buf, off)
            if op != Op.MESSAGE_INDEX or off + 9 + n > len(buf):
                break
            cid, size = _MSG_INDEX.unpack_from(buf, off + 9)
            if size % 16 or size + 6 != n:
                return {}
            counts[cid] = counts.get(cid, 0) + size // 16
            off += 9 + n
    except struct.error:
        return {}
    return counts


def chunk_damage(buf: Buf, block: Block, problem: str) -> Damage:
    """The `Damage` of an unreadable chunk: where, its log time range, what it held."""
    return Damage(
        "chunk",
        block.offset,
        block.length,
        problem,
        block.start_ns,
        block.end_ns,
        index_counts(buf, block),
    )
