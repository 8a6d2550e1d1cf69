"""`uavtool info`, `export`, `import` through the real command line group."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.recording.sample import write_sample
from uavtool.cli import cli


@pytest.fixture
def rec(tmp_path: Path) -> Path:
    path = tmp_path / "rec.mcap"
    write_sample(path, seconds=3.0)
    return path


def test_info_on_a_whole_recording(rec: Path) -> None:
    result = CliRunner().invoke(cli, ["info", str(rec)])
    assert result.exit_code == 0, result.output
    assert "health:    whole, indexed" in result.output
    assert "duration:  2.990 s" in result.output
    assert "frames:    3" in result.output
    assert "outcome:   result=matched, building=red" in result.output
    assert "/mavlink/raw" in result.output
    assert " 300 msgs" in result.output


def test_info_reports_a_cut_file_and_recovers_it(rec: Path, tmp_path: Path) -> None:
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(rec.read_bytes()[: rec.stat().st_size // 4])
    result = CliRunner().invoke(cli, ["info", str(cut)])
    assert result.exit_code == 0, result.output
    assert "TRUNCATED" in result.output
    assert "messages readable" in result.output
    assert "outcome:   unknown" in result.output
    fixed = tmp_path / "fixed.mcap"
    result = CliRunner().invoke(cli, ["info", "--recover", str(cut), "-o", str(fixed)])
    assert result.exit_code == 0, result.output
    assert "recovered" in result.output
    result = CliRunner().invoke(cli, ["info", str(fixed)])
    assert "health:    whole, indexed" in result.output
    assert "recovered" in result.output  # the metadata record naming the source


def test_export_and_import(rec: Path, tmp_path: Path) -> None:
    tlog, back = tmp_path / "out.tlog", tmp_path / "back.mcap"
    result = CliRunner().invoke(cli, ["export", str(rec), "--tlog", str(tlog)])
    assert result.exit_code == 0, result.output
    assert "wrote 300 MAVLink frames" in result.output
    result = CliRunner().invoke(cli, ["import", str(tlog), "-o", str(back)])
    assert result.exit_code == 0, result.output
    assert "imported 300 MAVLink frames" in result.output


@pytest.mark.parametrize(
    ("args", "content", "message"),
    [
        (["info"], b"", "empty file"),
        (["info"], b"not an mcap at all", "not an MCAP file"),
        (["export", "--tlog", "x.tlog"], b"\x89MCAP0\r\n", "no topic '/mavlink/raw'"),
        (["import", "-o", "x.mcap"], b"\x89MCAP0\r\n" * 40, "no MAVLink frames"),
    ],
)
def test_bad_input_is_one_line_exit_2(
    tmp_path: Path, args: list[str], content: bytes, message: str
) -> None:
    bad = tmp_path / "bad.bin"
    bad.write_bytes(content)
    result = CliRunner().invoke(cli, [args[0], str(bad), *args[1:]])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"uavtool: error: {bad}: ")
    assert message in lines[0]


def test_an_output_that_cannot_be_created_is_named_as_asked(rec: Path, tmp_path: Path) -> None:
    """The error names the file the user asked for, not its temporary ``NAME.PID.partial``."""
    out = tmp_path / "missing" / "out.tlog"
    result = CliRunner().invoke(cli, ["export", str(rec), "--tlog", str(out)])
    assert result.exit_code == 2, result.output
    assert result.output.strip().splitlines() == [
        f"uavtool: error: {out}: cannot create: No such file or directory"
    ]


def test_recover_needs_an_output(rec: Path) -> None:
    result = CliRunner().invoke(cli, ["info", "--recover", str(rec)])
    assert result.exit_code == 2
    assert "--recover and -o/--output go together" in result.output


@pytest.mark.parametrize("command", ["info", "export", "import"])
def test_help_has_an_example(command: str) -> None:
    result = CliRunner().invoke(cli, [command, "--help"])
    assert result.exit_code == 0
    assert "Example:" in result.output
    assert f"uavtool {command} " in result.output
