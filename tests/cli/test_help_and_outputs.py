"""Every command's help reads whole and its examples name files that exist; every command
run on the golden recordings prints no traceback and no warning (a clean install has no
scipy, for one: trimesh logs a traceback without it)."""

from __future__ import annotations

import shlex
import subprocess
import sys
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from uavtool.cli import cli

ROOT = Path(__file__).parents[2]
PAPER = "recordings/golden/paper.mcap"


def _commands(group: click.Group, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    found = []
    for name, command in sorted(group.commands.items()):
        found.append((*prefix, name))
        if isinstance(command, click.Group):
            found += _commands(command, (*prefix, name))
    return found


COMMANDS = _commands(cli)


def _help(path: tuple[str, ...]) -> str:
    result = CliRunner().invoke(cli, [*path, "--help"])
    assert result.exit_code == 0, result.output
    return result.output


def _examples(text: str) -> list[list[str]]:
    lines = [ln.split("#", 1)[0].strip() for ln in text.splitlines()]
    return [shlex.split(ln)[1:] for ln in lines if ln.startswith("uavtool ")]


@pytest.mark.parametrize("path", COMMANDS, ids=[" ".join(p) for p in COMMANDS])
def test_help_examples_name_files_that_exist(path: tuple[str, ...]) -> None:
    """A path into the repository (``recordings/…``, ``tests/…``) in an example exists, so
    the example runs as printed from a clone; other names are the user's own files."""
    for argv in _examples(_help(path)):
        for word in argv:
            if word.startswith(("recordings/", "tests/")) and "*" not in word:
                assert (ROOT / word).exists(), f"`uavtool {' '.join(argv)}`: no {word}"


def test_top_level_help_lines_read_whole() -> None:
    text = _help(())
    listing = text.split("Commands:", 1)[1]
    assert "..." not in listing
    for name in cli.commands:
        assert f"\n  {name} " in listing


def _run(*args: str, cwd: Path) -> str:
    done = subprocess.run(
        [sys.executable, "-m", "uavtool", *args],
        cwd=cwd, capture_output=True, text=True, timeout=240, check=False,
    )  # fmt: skip
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    return out


@pytest.mark.slow
def test_no_traceback_or_warning_from_any_command(tmp_path: Path) -> None:
    runs = [
        *(("info", str(p)) for p in sorted((ROOT / "recordings" / "golden").glob("*.mcap"))),
        ("info", "--json", PAPER),
        ("export", PAPER, "--tlog", str(tmp_path / "paper.tlog")),
        ("export", PAPER, "--layout", str(tmp_path / "paper.layout.json")),
        ("import", str(tmp_path / "paper.tlog"), "-o", str(tmp_path / "back.mcap")),
        ("view", PAPER, "--save", str(tmp_path / "paper.rrd")),
        ("replay", "--check", PAPER),
        ("scene", "list"),
        ("scene", "target", "paper", "-o", str(tmp_path / "target.png")),
        ("scene", "render", "paper", "--pos", "0,0,45", "-o", str(tmp_path / "nadir.png")),
        ("vision", "vectorize", str(tmp_path / "nadir.png")),
    ]
    for args in runs:
        out = _run(*args, cwd=ROOT)
        for bad in ("Traceback", "WARNING", "Warning:"):
            assert bad not in out, f"uavtool {' '.join(args)}:\n{out}"


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["fly", "--nosuch"], "No such option '--nosuch'"),
        (["fly", "--rerun", "nosuch"], "Invalid value for --rerun: 'nosuch'"),
        (["replay"], "Missing argument 'RECORDING'"),
        (["nosuchcommand"], "No such command 'nosuchcommand'"),
    ],
)
def test_a_command_line_click_cannot_parse_is_one_line(args: list[str], says: str) -> None:
    """Not click's usage block (three lines and a blank one): one line naming the problem
    and where the help is, exit 2, as every other error."""
    done = subprocess.run(
        [sys.executable, "-m", "uavtool", *args], capture_output=True, text=True, check=False
    )
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("uavtool: error: ") and says in lines[0]
    command = "uavtool" if args[0] == "nosuchcommand" else f"uavtool {args[0]}"
    assert lines[0].endswith(f"(see '{command} --help')")
