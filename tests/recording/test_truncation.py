"""Cut a recording anywhere: it is reported, and recovery keeps every message it holds whole."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap.records import Chunk
from mcap.records import Message as McapMessage
from mcap.stream_reader import StreamReader, breakup_chunk

from tests.recording.sample import write_sample
from uavtool.recording import NotMcapError, RecordingReader, recover, summarize
from uavtool.recording.info import format_info

Key = tuple[str, int, int, bytes]  # topic, sequence, log time, data


def _truth(path: Path) -> tuple[list[list[Key]], list[tuple[int, int]], int]:
    """Messages per chunk (file order), each chunk's (start, end) offsets, summary start."""
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    topics = {c.id: c.topic for c in summary.channels.values()}
    spans = sorted(
        (c.chunk_start_offset, c.chunk_start_offset + c.chunk_length) for c in summary.chunk_indexes
    )
    with path.open("rb") as f:
        chunks: list[list[Key]] = [
            [
                (topics[m.channel_id], m.sequence, m.log_time, m.data)
                for m in breakup_chunk(record)
                if isinstance(m, McapMessage)
            ]
            for record in StreamReader(f, emit_chunks=True).records
            if isinstance(record, Chunk)
        ]
    with path.open("rb") as f:
        data = f.read()
    footer_start = len(data) - 8 - 29
    summary_start = int.from_bytes(data[footer_start + 9 : footer_start + 17], "little")
    return chunks, spans, summary_start


def _keys(path: Path) -> list[Key]:
    with RecordingReader(path) as reader:
        return [(m.channel.topic, m.sequence, m.log_time_ns, m.data) for m in reader.messages()]


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("trunc") / "rec.mcap"
    write_sample(path, seconds=6.0, chunk_interval_ns=1_000_000_000)
    return path


def _offsets(path: Path) -> list[int]:
    _chunks, spans, summary_start = _truth(path)
    size = path.stat().st_size
    second_chunk = (spans[1][0] + spans[1][1]) // 2
    explicit = [3, 12, second_chunk, spans[0][0] + 20, summary_start + 10, size - 20, size - 3]
    rng = random.Random(5)
    return explicit + sorted(rng.randrange(1, size) for _ in range(20 - len(explicit)))


def test_twenty_cuts_are_reported_and_recovered(recording: Path, tmp_path: Path) -> None:
    chunks, spans, summary_start = _truth(recording)
    original = [k for chunk in chunks for k in chunk]
    offsets = _offsets(recording)
    assert len(offsets) == 20
    assert any(o > summary_start for o in offsets)
    assert any(o < 30 for o in offsets)
    data = recording.read_bytes()
    for cut in offsets:
        cut_path = tmp_path / f"cut{cut}.mcap"
        cut_path.write_bytes(data[:cut])
        info = summarize(cut_path)
        assert not info.whole, cut
        assert "TRUNCATED" in format_info(info)
        fixed = tmp_path / f"fixed{cut}.mcap"
        result = recover(cut_path, fixed)
        got = _keys(fixed)
        whole_before_cut = [
            k for chunk, span in zip(chunks, spans, strict=True) if span[1] <= cut for k in chunk
        ]
        assert got == original[: len(got)], cut  # nothing invented, nothing reordered
        assert len(got) >= len(whole_before_cut), cut
        assert result.messages == info.message_count == len(got)
        if cut > summary_start:
            assert got == original
        with fixed.open("rb") as f:  # the recovered file is whole and indexed for stock tools
            stock = make_reader(f)
            summary = stock.get_summary()
            assert summary is not None
            assert summary.statistics is not None
            assert summary.statistics.message_count == len(got)
            assert sum(1 for _ in stock.iter_messages()) == len(got)


def test_a_cut_large_chunk_still_gives_its_whole_blocks(tmp_path: Path) -> None:
    path = tmp_path / "big.mcap"
    write_sample(path, seconds=6.0, rate_hz=500, chunk_interval_ns=10**12, chunk_bytes=1 << 30)
    data = path.read_bytes()
    chunks, spans, _ = _truth(path)
    assert len(spans) == 1  # a single chunk, several zstd blocks
    cut_path = tmp_path / "cut.mcap"
    cut_path.write_bytes(data[: (spans[0][0] + spans[0][1]) // 2])
    info = summarize(cut_path)
    assert info.partial_chunk
    assert info.message_count > 0
    assert _keys(cut_path) == chunks[0][: info.message_count]


@pytest.mark.parametrize(
    ("content", "problem"),
    [(b"", "empty file"), (b"PK\x03\x04 a zip file", "not an MCAP file"), (None, "cannot open")],
)
def test_bad_files_are_one_line_errors(tmp_path: Path, content: bytes | None, problem: str) -> None:
    path = tmp_path / "bad.mcap"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(NotMcapError, match=problem) as exc:
        summarize(path)
    assert str(exc.value).startswith(str(path))
    assert "\n" not in str(exc.value)
