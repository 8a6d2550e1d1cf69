"""A cut recording is never passed off as whole: `export`, `view` and `replay` read what it
holds up to its cut, write that, say so on their last line (``incomplete: …``) and exit 3;
a whole file exits 0 through the same commands."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import CliRunner
from mcap.reader import make_reader

from uavtool.cli import cli
from uavtool.errors import INCOMPLETE_EXIT
from uavtool.recording import RecordingReader
from uavtool.recording.info import summarize

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def _summary_start(data: bytes) -> int:
    footer = len(data) - 8 - 29  # the footer record: opcode, length, summary start, ...
    return int.from_bytes(data[footer + 9 : footer + 17], "little")


def _cut_in_half(path: Path) -> Path:
    data = GOLDEN.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    return path


def _zeroed_over_summary(path: Path) -> Path:
    """The attack run's case: a range of zeros over the last chunks and the summary, the
    footer left as written (from the start of a chunk: the file reads as cut there)."""
    data = bytearray(GOLDEN.read_bytes())
    with GOLDEN.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    starts = sorted(c.chunk_start_offset for c in summary.chunk_indexes)
    start = max(s for s in starts if s < _summary_start(bytes(data)) - 300_000)
    data[start : len(data) - 40] = bytes(len(data) - 40 - start)
    path.write_bytes(bytes(data))
    return path


def _commands(tmp: Path) -> list[list[str]]:
    return [
        ["export", "{rec}", "--tlog", f"{tmp}/out.tlog"],
        ["export", "{rec}", "--frames", f"{tmp}/frames", "--layout", f"{tmp}/l.json"],
        ["view", "{rec}", "--save", f"{tmp}/v.rrd"],
        ["replay", "{rec}"],
    ]


@pytest.mark.parametrize("damage", [_cut_in_half, _zeroed_over_summary])
def test_a_cut_file_is_read_to_its_cut_and_said_so(
    tmp_path: Path, damage: Callable[[Path], Path]
) -> None:
    rec = damage(tmp_path / "cut.mcap")
    assert not summarize(rec).whole
    for command in _commands(tmp_path):
        result = CliRunner().invoke(cli, [a.replace("{rec}", str(rec)) for a in command])
        assert result.exit_code == INCOMPLETE_EXIT, (command, result.output)
        last = result.output.strip().splitlines()[-1]
        assert last.startswith(f"incomplete: {rec} is truncated"), last
        assert "uavtool info --recover" in last
        assert "identical" not in result.output
    tlog = (tmp_path / "out.tlog").stat().st_size
    whole = tmp_path / "whole.tlog"
    assert CliRunner().invoke(cli, ["export", str(GOLDEN), "--tlog", str(whole)]).exit_code == 0
    assert 0 < tlog < whole.stat().st_size  # what it held, no more


def test_a_whole_file_says_nothing_of_the_kind(tmp_path: Path) -> None:
    with RecordingReader(GOLDEN) as reader:
        assert reader.health.whole
    for command in _commands(tmp_path)[:3]:
        result = CliRunner().invoke(cli, [a.replace("{rec}", str(GOLDEN)) for a in command])
        assert result.exit_code == 0, (command, result.output)
        assert "incomplete" not in result.output


def test_a_cut_file_compared_in_view_is_said_so(tmp_path: Path) -> None:
    rec = _cut_in_half(tmp_path / "cut.mcap")
    args = ["view", str(GOLDEN), "--compare", str(rec), "--save", str(tmp_path / "v.rrd")]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == INCOMPLETE_EXIT, result.output
    assert result.output.strip().splitlines()[-1].startswith(f"incomplete: {rec} is truncated")
