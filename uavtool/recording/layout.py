"""Finds what an MCAP file holds, whole or cut: schemas, channels, metadata and data blocks.

A whole file (footer + magic at the end, summary CRC good) is read from its summary without
touching the chunks; its metadata records, which have no CRC, are parsed within their bounds
and any that do not parse are listed as `Damage`. Anything else — a crash mid-write, a cut
anywhere, a file without a summary, a summary whose CRC does not match — is scanned record by
record from the start up to the last whole record: a chunk that fails its checks is listed as
`Damage` and skipped (the scan goes on after it), and a chunk cut in the middle still gives
up the messages in its complete compression blocks. The stock `mcap` readers fail on such
files; this one never raises past the cut.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field

from uavtool.recording.chunks import Block, ChunkDamaged, Damage, chunk_damage, read_chunk
from uavtool.recording.records import (
    MAGIC,
    Buf,
    Channel,
    NotMcap,
    Op,
    Schema,
    chunk_payload,
    decompress_prefix,
    iter_records,
    op_name,
    parse_channel,
    parse_metadata,
    parse_schema,
    read_str,
)

__all__ = ["Block", "Buf", "Channel", "Damage", "Health", "Layout", "NotMcap", "Schema"]

_REC = struct.Struct("<BQ")
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_FOOTER = struct.Struct("<BQQQI")
_FOOTER_SIZE = _FOOTER.size  # opcode + length + 20 bytes


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
    damage: list[Damage] = field(default_factory=list)  # found while finding the layout
    data_crc: int = 0  # the data section's CRC from its DataEnd record (0: not computed)
    data_end: int = 0  # where the DataEnd record starts (0: unknown)
    summary_problem: str = ""  # why a summary that is there was not used ("" if none)


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
    if crc and zlib.crc32(buf[summary_start : fpos + _FOOTER_SIZE - 4]) != crc:
        layout.summary_problem = "summary CRC mismatch"
        return False
    try:
        return _parse_summary(buf, layout, summary_start, fpos)
    except struct.error as exc:  # a summary without a CRC that does not parse: scan instead
        layout.summary_problem = f"summary unreadable ({exc})"
        return False


def _parse_summary(buf: Buf, layout: Layout, summary_start: int, fpos: int) -> bool:
    size = len(buf)
    stats_chunks, stats_channels = -1, -1
    chunk_blocks: list[Block] = []
    meta_index: list[tuple[int, int, str]] = []
    for op, s, e in iter_records(buf, summary_start, fpos):
        if op == Op.SCHEMA:
            schema = parse_schema(buf, s, e)
            layout.schemas[schema.id] = schema
        elif op == Op.CHANNEL:
            channel = parse_channel(buf, s, e)
            layout.channels[channel.id] = channel
        elif op == Op.STATISTICS:
            (layout.start_ns, layout.end_ns) = struct.unpack_from("<QQ", buf, s + 26)
            (stats_channels,) = _U32.unpack_from(buf, s + 10)
            (stats_chunks,) = _U32.unpack_from(buf, s + 22)
            (n_counts,) = _U32.unpack_from(buf, s + 42)
            for k in range(s + 46, min(e, s + 46 + n_counts), 10):
                cid, count = struct.unpack_from("<HQ", buf, k)
                layout.counts[cid] = count
        elif op == Op.CHUNK_INDEX:
            start_ns, end_ns, offset, length = struct.unpack_from("<QQQQ", buf, s)
            (n_idx,) = _U32.unpack_from(buf, s + 32)
            ids = frozenset(_U16.unpack_from(buf, k)[0] for k in range(s + 36, s + 36 + n_idx, 10))
            chunk_blocks.append(Block(offset, length, start_ns, end_ns, True, ids or None))
        elif op == Op.METADATA_INDEX:
            offset, length = struct.unpack_from("<QQ", buf, s)
            meta_index.append((offset, length, read_str(buf, s + 16, e)[0]))
    if stats_chunks != len(chunk_blocks) or (not layout.counts and stats_chunks):
        return False  # no statistics, or messages outside chunks: scan instead
    if sum(layout.counts.values()) and not chunk_blocks:
        return False
    if stats_channels != len(layout.channels):  # channels not repeated in the summary
        return False
    layout.blocks = sorted(chunk_blocks, key=lambda b: b.offset)
    for offset, length, name in meta_index:
        _read_indexed_metadata(buf, layout, offset, length, name)
    _read_header(buf, layout)
    _read_data_end(buf, layout, summary_start)
    layout.health = Health(True, True, size, size)
    return True


def _read_indexed_metadata(buf: Buf, layout: Layout, offset: int, length: int, name: str) -> None:
    try:
        op, n = _REC.unpack_from(buf, offset)
        if op != Op.METADATA or 9 + n != length:
            raise struct.error("the index points at no metadata record of that length")
        got_name, record = parse_metadata(buf, offset + 9, offset + length)
        if got_name != name:
            raise struct.error(f"its name reads {got_name!r}, the index says {name!r}")
    except struct.error as exc:
        layout.damage.append(Damage("metadata", offset, length, str(exc), name=name))
        return
    layout.metadata.append((name, record))


def _read_header(buf: Buf, layout: Layout) -> None:
    for op, s, e in iter_records(buf, 8, min(len(buf), 1 << 16)):
        if op == Op.HEADER:
            try:
                layout.profile, off = read_str(buf, s, e)
                layout.library, _ = read_str(buf, off, e)
            except struct.error:
                layout.library = "?"
        break


def _read_data_end(buf: Buf, layout: Layout, summary_start: int) -> None:
    """The DataEnd record just before the summary, if it is there."""
    pos = summary_start - 13
    if pos > 8 and _REC.unpack_from(buf, pos) == (Op.DATA_END, 4):
        layout.data_end = pos
        (layout.data_crc,) = _U32.unpack_from(buf, pos + 9)


# --- cut or summary-less files: a linear scan -----------------------------------------------


def _scan_chunk(
    layout: Layout, records: bytes, offset: int, length: int, data: bytes | None
) -> Block:
    ids: set[int] = set()
    start_ns, end_ns = 1 << 64, 0
    for op, s, e in iter_records(records, 0, len(records)):
        if op == Op.MESSAGE:
            cid, _seq, t = struct.unpack_from("<HIQ", records, s)
            ids.add(cid)
            layout.counts[cid] = layout.counts.get(cid, 0) + 1
            start_ns, end_ns = min(start_ns, t), max(end_ns, t)
        elif op == Op.SCHEMA:
            schema = parse_schema(records, s, e)
            layout.schemas[schema.id] = schema
        elif op == Op.CHANNEL:
            channel = parse_channel(records, s, e)
            layout.channels[channel.id] = channel
    return Block(offset, length, start_ns if ids else 0, end_ns, True, frozenset(ids), data)


def _rescue_chunk(buf: Buf, layout: Layout, pos: int, s: int) -> bool:
    """Keep the whole messages at the start of a chunk cut by the end of the file."""
    try:
        comp, rs, rn, _usize, _crc = chunk_payload(buf, s, len(buf))
    except struct.error:  # cut inside the chunk's own header fields
        return False
    data = decompress_prefix(comp, buf[rs : rs + rn])
    if not data:
        return False
    try:
        block = _scan_chunk(layout, data, pos, len(buf) - pos, data)
    except struct.error:
        return False
    if not block.channel_ids:
        return False
    layout.blocks.append(block)
    return True


def _scan_record(buf: Buf, layout: Layout, op: int, pos: int, s: int, e: int) -> None:
    """Take one whole data-section record into ``layout``; raises `struct.error` if its
    fields do not parse, `ChunkDamaged` for a chunk that fails its checks."""
    if op == Op.HEADER:
        layout.profile, off = read_str(buf, s, e)
        layout.library, _ = read_str(buf, off, e)
    elif op == Op.SCHEMA:
        schema = parse_schema(buf, s, e)
        layout.schemas[schema.id] = schema
    elif op == Op.CHANNEL:
        channel = parse_channel(buf, s, e)
        layout.channels[channel.id] = channel
    elif op == Op.MESSAGE:
        cid, _seq, t = struct.unpack_from("<HIQ", buf, s)
        layout.counts[cid] = layout.counts.get(cid, 0) + 1
        layout.blocks.append(Block(pos, e - pos, t, t, False, frozenset((cid,))))
    elif op == Op.CHUNK:
        records = read_chunk(buf, Block(pos, e - pos, 0, 0, True, None))
        layout.blocks.append(_scan_chunk(layout, records, pos, e - pos, None))
    elif op == Op.METADATA:
        layout.metadata.append(parse_metadata(buf, s, e))


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
        if e > size:
            problem = f"cut at byte {size} inside a {op_name(op)} record starting at byte {pos}"
            if op == Op.CHUNK:
                partial = _rescue_chunk(buf, layout, pos, s)
            break
        if op == Op.DATA_END:
            layout.data_end = pos
            if n >= 4:
                (layout.data_crc,) = _U32.unpack_from(buf, s)
        if op in (Op.DATA_END, Op.FOOTER):
            break  # the data section is over; everything in it was read
        try:
            _scan_record(buf, layout, op, pos, s, e)
        except ChunkDamaged as exc:
            start_ns, end_ns = struct.unpack_from("<QQ", buf, s) if n >= 16 else (0, 0)
            block = Block(pos, e - pos, start_ns, end_ns, True, None)
            layout.damage.append(chunk_damage(buf, block, str(exc)))
        except struct.error as exc:
            kind = "metadata" if op == Op.METADATA else op_name(op)
            layout.damage.append(Damage(kind, pos, e - pos, str(exc)))
        pos = e
    whole = not problem and bytes(buf[-8:]) == MAGIC
    if not whole and not problem:
        problem = f"cut at byte {size} in the summary (all data readable)"
    layout.health = Health(whole, False, size, pos, problem, partial)
    times = [(b.start_ns, b.end_ns) for b in layout.blocks if b.channel_ids]
    if times:
        layout.start_ns = min(t[0] for t in times)
        layout.end_ns = max(t[1] for t in times)


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
        layout = Layout(summary_problem=layout.summary_problem)
        _scan(buf, layout)
    return layout
