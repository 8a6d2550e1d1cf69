"""Corrupt recordings: a flipped bit is found, located and never read as data; the good part
is recovered; a corrupt summary or metadata record gives one line, never a traceback."""

from __future__ import annotations

import shutil
import struct
import zlib
from pathlib import Path

import pytest
from click.testing import CliRunner
from mcap.reader import make_reader
from mcap.records import Chunk
from mcap.records import Message as McapMessage
from mcap.stream_reader import StreamReader, breakup_chunk

from tests.recording.sample import T0_NS, write_sample
from uavtool.cli import cli
from uavtool.recording import RecordingReader, RecordingWriter, recover, summarize
from uavtool.recording.errors import CorruptRecordingError
from uavtool.recording.records import chunk_payload, iter_records
from uavtool.replay import load_flight
from uavtool.replay.write import write_replay

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden" / "paper.mcap"


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, list(args))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stdout, result.stderr


def _one_line_error(err: str, path: Path) -> None:
    assert err.startswith(f"uavtool: error: {path}: "), err
    assert err.count("\n") == 1, err
    assert "Traceback" not in err


def _chunks(path: Path) -> list[tuple[int, int, dict[int, int]]]:
    """(offset, length, messages per channel id) of every chunk, from the stock reader."""
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    out = []
    with path.open("rb") as f:
        reader = make_reader(f)
        for index in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
            counts: dict[int, int] = {}
            for cid, offset in index.message_index_offsets.items():
                f.seek(offset + 9 + 2)
                (size,) = struct.unpack("<I", f.read(4))
                counts[cid] = size // 16
            out.append((index.chunk_start_offset, index.chunk_length, counts))
    del reader
    return out


def _messages_by_chunk(path: Path) -> list[list[tuple[str, int, int, bytes]]]:
    """Every chunk's messages as (topic, sequence, log time, data), by the stock reader."""
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    topics = {c.id: c.topic for c in summary.channels.values()}
    with path.open("rb") as f:
        return [
            [
                (topics[m.channel_id], m.sequence, m.log_time, m.data)
                for m in breakup_chunk(record)
                if isinstance(m, McapMessage)
            ]
            for record in StreamReader(f, emit_chunks=True).records
            if isinstance(record, Chunk)
        ]


def _flip_inside_chunk(src: Path, dst: Path, which: int) -> tuple[int, int, dict[int, int]]:
    """Copy ``src`` with one bit flipped in the middle of chunk number ``which``'s
    compressed bytes; returns that chunk's (offset, length, counts)."""
    chunk = _chunks(src)[which]
    data = bytearray(src.read_bytes())
    offset, length, _ = chunk
    _comp, start, size, _usize, _crc = chunk_payload(bytes(data), offset + 9, offset + length)
    data[start + size // 2] ^= 0x10
    dst.write_bytes(data)
    return chunk


@pytest.fixture
def flipped(tmp_path: Path) -> tuple[Path, tuple[int, int, dict[int, int]]]:
    """The paper golden with a bit flipped in its last-but-two chunk (mission outputs)."""
    path = tmp_path / "flipped.mcap"
    return path, _flip_inside_chunk(GOLDEN, path, -3)


def test_info_finds_and_locates_a_flipped_bit(
    flipped: tuple[Path, tuple[int, int, dict[int, int]]],
) -> None:
    path, (offset, length, counts) = flipped
    info = summarize(path)
    assert len(info.damage) == 1
    assert info.damage[0].startswith(f"byte {offset}: corrupt chunk of {length} bytes")
    assert "CRC mismatch" in info.damage[0] or "unreadable" in info.damage[0]
    with GOLDEN.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    index = next(c for c in summary.chunk_indexes if c.chunk_start_offset == offset)
    t0 = summary.statistics.message_start_time
    start_s, end_s = (index.message_start_time - t0) / 1e9, (index.message_end_time - t0) / 1e9
    assert f"log time {start_s:.3f}–{end_s:.3f} s" in info.damage[0]
    assert info.messages_lost == sum(counts.values())
    code, out, err = _run("info", str(path))
    assert code == 2
    assert "health:    DAMAGED" in out
    assert f"{sum(counts.values())} messages lost on /mavlink/in/ATTITUDE" in out
    _one_line_error(err, path)


def test_info_without_verify_reads_the_summary_only(
    flipped: tuple[Path, tuple[int, int, dict[int, int]]],
) -> None:
    path, _ = flipped
    code, out, _ = _run("info", "--no-verify", str(path))
    assert code == 0
    assert "health:    whole, indexed, chunks not checked" in out
    code, out, _ = _run("info", str(GOLDEN))
    assert code == 0
    assert "health:    whole, indexed, CRCs checked" in out


@pytest.mark.parametrize(
    "command",
    [
        ["replay", "--check", "-q"],
        ["replay", "--refly"],
        ["export", "--tlog", "{tmp}/out.tlog"],
        ["view", "--save", "{tmp}/out.rrd"],
    ],
)
def test_every_reader_refuses_the_lost_data(
    flipped: tuple[Path, tuple[int, int, dict[int, int]]], command: list[str]
) -> None:
    path, (offset, _, _) = flipped
    args = [a.format(tmp=path.parent) for a in command]
    code, _, err = _run(args[0], str(path), *args[1:])
    assert code == 2
    _one_line_error(err, path)
    assert f"byte {offset}: corrupt chunk" in err
    assert "uavtool info --recover" in err
    assert sorted(p.name for p in path.parent.iterdir()) == ["flipped.mcap"]  # nothing left


def test_topics_outside_the_bad_chunk_still_read(
    flipped: tuple[Path, tuple[int, int, dict[int, int]]],
) -> None:
    path, _ = flipped
    with RecordingReader(path) as reader:
        assert sum(1 for _ in reader.messages(["/mission/target"])) == 1
        with pytest.raises(CorruptRecordingError, match="corrupt chunk"):
            sum(1 for _ in reader.messages(["/mavlink/raw"]))


def test_recover_keeps_every_good_chunk(
    flipped: tuple[Path, tuple[int, int, dict[int, int]]],
) -> None:
    path, (offset, _, counts) = flipped
    bad = [c[0] for c in _chunks(GOLDEN)].index(offset)
    fixed = path.parent / "fixed.mcap"
    code, out, _ = _run("info", "--recover", str(path), "-o", str(fixed))
    assert code == 0
    assert f"dropped byte {offset}: corrupt chunk" in out
    good = [m for i, chunk in enumerate(_messages_by_chunk(GOLDEN)) if i != bad for m in chunk]
    info = summarize(fixed)
    assert info.whole and not info.damage
    assert info.message_count == summarize(GOLDEN).message_count - sum(counts.values())
    with RecordingReader(fixed) as reader:
        got = [(m.channel.topic, m.sequence, m.log_time_ns, m.data) for m in reader.messages()]
        assert dict(reader.metadata)["recovered"]["dropped"].startswith(f"byte {offset}")
    assert got == good


def test_a_scan_skips_a_bad_chunk_and_goes_on(tmp_path: Path) -> None:
    """A cut file (no summary) with a bad chunk in the middle: the chunks after it are kept."""
    whole = tmp_path / "rec.mcap"
    write_sample(whole, seconds=6.0)
    bad = tmp_path / "bad.mcap"
    offset, _, counts = _flip_inside_chunk(whole, bad, 2)
    last_chunk = _chunks(whole)[-1]
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(bad.read_bytes()[: last_chunk[0] + last_chunk[1] + 5])
    info = summarize(cut)
    assert not info.whole
    assert [d.split(":")[0] for d in info.damage] == [f"byte {offset}"]
    assert info.messages_lost == sum(counts.values())
    with pytest.raises(CorruptRecordingError):
        list(RecordingReader(cut).messages())
    result = recover(cut, tmp_path / "fixed.mcap")
    total = sum(sum(c.values()) for _, _, c in _chunks(whole))
    assert result.messages == total - sum(counts.values())
    assert result.messages_lost == sum(counts.values())


def test_a_corrupt_summary_is_reported_and_the_data_still_read(tmp_path: Path) -> None:
    path = tmp_path / "summary.mcap"
    data = bytearray(GOLDEN.read_bytes())
    fpos = len(data) - 8 - 29
    (summary_start,) = struct.unpack_from("<Q", data, fpos + 9)
    data[(summary_start + fpos) // 2] ^= 0xFF
    path.write_bytes(data)
    code, out, err = _run("info", str(path))
    assert code == 2
    assert "summary CRC mismatch: every record read by a scan instead" in out
    _one_line_error(err, path)
    with RecordingReader(GOLDEN) as a, RecordingReader(path) as b:
        assert [(m.sequence, m.data) for m in a.messages()] == [
            (m.sequence, m.data) for m in b.messages()
        ]
        assert a.metadata == b.metadata
    code, out, _ = _run("export", str(path), "--tlog", str(tmp_path / "x.tlog"))
    assert code == 0, out


@pytest.mark.parametrize("name", ["mission", "scene"])
def test_a_flipped_byte_in_metadata_is_one_line(tmp_path: Path, name: str) -> None:
    with GOLDEN.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    index = next(m for m in summary.metadata_indexes if m.name == name)
    data = bytearray(GOLDEN.read_bytes())
    data[index.offset + 9 + 4 + len(name) + 1] ^= 0x40  # the length of its map
    path = tmp_path / "meta.mcap"
    path.write_bytes(data)
    code, out, err = _run("info", str(path))
    assert code == 2
    assert f"damaged metadata record {name!r}" in out
    _one_line_error(err, path)
    needs = [["replay", "--refly"], ["view", "--save", str(tmp_path / "x.rrd")]]
    if name == "mission":  # the parameters: replay needs them, not the scene
        needs.append(["replay", "--check", "-q"])
    for command in needs:
        code, _, err = _run(command[0], str(path), *command[1:])
        assert code == 2
        _one_line_error(err, path)
        assert f"metadata record {name!r} is damaged" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["meta.mcap"]


def test_check_fails_without_an_outcome(tmp_path: Path) -> None:
    """A whole recording whose outputs stop before the Outcome cannot pass --check."""
    flight = load_flight(GOLDEN)
    cut = tmp_path / "no-outcome.mcap"
    outputs = [o for o in flight.outputs if o.data.get("type") != "Outcome"]
    write_replay(GOLDEN, cut, outputs, {}, flight.params)
    code, _, err = _run("replay", "--check", "-q", str(cut))
    assert code == 1
    _one_line_error(err, cut)
    assert "no Outcome" in err


def test_a_copy_is_not_damaged(tmp_path: Path) -> None:
    path = tmp_path / "copy.mcap"
    shutil.copy(GOLDEN, path)
    info = summarize(path)
    assert info.verified and not info.damage and not info.summary_problem


def test_reading_less_than_the_statistics_count_fails(tmp_path: Path) -> None:
    """A summary (CRC good) that counts one message more than the chunks hold: a reader that
    reads everything says so instead of passing the shorter read off as whole."""
    path = tmp_path / "rec.mcap"
    write_sample(path)
    data = bytearray(path.read_bytes())
    fpos = len(data) - 8 - 29
    (summary_start,) = struct.unpack_from("<Q", data, fpos + 9)
    stats = next(s - 9 for op, s, _ in iter_records(bytes(data), summary_start, fpos) if op == 0x0B)
    (first,) = struct.unpack_from("<Q", data, stats + 9)  # message count
    struct.pack_into("<Q", data, stats + 9, first + 1)
    count_at = stats + 9 + 46 + 2  # the first channel's count
    (n,) = struct.unpack_from("<Q", data, count_at)
    struct.pack_into("<Q", data, count_at, n + 1)
    struct.pack_into("<I", data, fpos + 25, zlib.crc32(bytes(data[summary_start : fpos + 25])))
    path.write_bytes(data)
    with RecordingReader(path) as reader:
        assert reader.health.indexed  # the doctored summary was believed
        with pytest.raises(CorruptRecordingError, match=r"read \d+ of the \d+ messages"):
            list(reader.messages())
    code, _, err = _run("export", str(path), "--tlog", str(tmp_path / "x.tlog"))
    assert code == 2  # channel 1 is /mavlink/raw: the sample writes a frame first
    _one_line_error(err, path)
    assert not (tmp_path / "x.tlog").exists()


def test_a_flipped_metadata_byte_is_found_and_refused(tmp_path: Path) -> None:
    """No chunk CRC covers a metadata record; the data section's CRC (which uavtool writes)
    does. A recorded max_looks 3 -> 2 changed nothing in a replay (the flight needed 2 looks),
    so `replay --check` said identical on a file whose parameters were not the ones flown."""
    path = tmp_path / "flight.mcap"
    flown = CliRunner().invoke(cli, ["fly", "-q", "--output", str(path)])
    assert flown.exit_code == 0, flown.output
    code, out, _ = _run("info", str(path))
    assert code == 0 and "health:    whole, indexed, CRCs checked" in out
    data = bytearray(path.read_bytes())
    at = data.index(b'"max_looks": 3') + len(b'"max_looks": ')
    data[at] = ord("2")
    path.write_bytes(bytes(data))
    code, out, err = _run("info", str(path))
    assert code == 2 and "health:    DAMAGED" in out and "data section" in out
    code, out, err = _run("replay", "--check", str(path))
    assert code == 2 and "identical" not in out
    _one_line_error(err, path)


def test_info_prints_no_terminal_escape_from_the_file(tmp_path: Path) -> None:
    """A recording's words reach the terminal as text: OSC 0 (window title), OSC 52
    (clipboard), BEL, NUL, a forged line break and a right-to-left override are escaped."""
    path = tmp_path / "hostile.mcap"
    hostile = "\x1b]0;owned\x07\x1b]52;c;ZWNobyBoaQ==\x07\x00\nhealth:    whole\u202etxt.exe"
    with RecordingWriter(path, metadata={"outcome": {"reason": hostile}}, fsync=False) as w:
        w.add_json_topic("/x", schema_name="x", schema={})
        w.write_json("/x", {"a": 1}, log_time_ns=T0_NS)
    code, out, _ = _run("info", str(path))
    assert code == 0, out
    for unsafe in ("\x1b", "\x07", "\x00", "\u202e"):
        assert unsafe not in out
    assert "\\x1b]0;owned\\x07" in out and "\\x0ahealth:" in out and "\\u202etxt" in out
    assert [line for line in out.splitlines() if line.startswith("health:")] == [
        "health:    whole, indexed, CRCs checked"
    ]  # no forged line
