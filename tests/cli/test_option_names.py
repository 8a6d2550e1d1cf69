"""One name per meaning across commands (issue 31): what a command writes is -o/--output,
mission and spec values are --set (--set-file for a JSON file of them), durations are
SECONDS, the web viewer's ports --web-port and --grpc-port. The old spellings work for one
release and say so in one line on stderr, once however often they are used."""

from __future__ import annotations

import json
import shlex
import socket
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import click
import pytest
from click.testing import CliRunner, Result

from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.cli.spelling import OldSpelling, looks_like_setting, modernise
from uavtool.images import png_encode
from uavtool.world import load_scene, render

PAPER = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"
SPEC = '[scenes]\nbuiltin = ["paper"]\n[grid]\nseed = [1, 2]\n'


def _invoke(*args: str) -> Result:
    return CliRunner().invoke(cli, list(args))


def _warnings(result: Result) -> list[str]:
    return [line for line in result.stderr.splitlines() if line.startswith("uavtool: warning:")]


def _one_error(result: Result) -> str:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [ln for ln in result.stderr.splitlines() if not ln.startswith("uavtool: warning:")]
    assert len(lines) == 1 and lines[0].startswith("uavtool: error: "), result.stderr
    return lines[0].removeprefix("uavtool: error: ")


def _commands(group: click.Group, prefix: tuple[str, ...] = ()) -> Iterator[tuple[str, ...]]:
    for name, command in sorted(group.commands.items()):
        if isinstance(command, click.Group):
            yield from _commands(command, (*prefix, name))
        else:
            yield (*prefix, name)


COMMANDS = list(_commands(cli))


def _help(path: tuple[str, ...]) -> str:
    result = _invoke(*path, "--help")
    assert result.exit_code == 0, result.output
    return result.stdout


# --- help: only the new names -------------------------------------------------------------


@pytest.mark.parametrize("path", COMMANDS, ids=[" ".join(p) for p in COMMANDS])
def test_help_shows_one_name_per_meaning(path: tuple[str, ...]) -> None:
    text = _help(path)
    lines = [line.strip() for line in text.split("Options:", 1)[1].splitlines()]
    listed = " ".join(line.split("  ")[0] for line in lines if line.startswith("-"))
    for old in ("--out ", "--override", "--port "):
        assert old not in listed, f"uavtool {' '.join(path)}: {old.strip()}"
    if "--timeout" in listed:
        assert "--timeout SECONDS" in listed
    if "--duration" in listed:
        assert "--duration SECONDS" in listed
    if "-o," in listed:
        assert "-o, --output" in listed  # -o means nothing else anywhere


@pytest.mark.parametrize(
    "path",
    [
        *[("fly",), ("record",), ("import",), ("replay",), ("sweep",), ("vision", "vectorize")],
        *[("vision", "model"), ("scene", "render"), ("scene", "target"), ("scene", "random")],
    ],
)
def test_what_a_command_writes_is_dash_o_output(path: tuple[str, ...]) -> None:
    assert "-o, --output" in _help(path)


def test_sitl_keeps_params_for_its_vehicle_parameter_file() -> None:
    text = _help(("sitl",))
    assert "--params PATH" in text and "NAME VALUE per line" in text
    assert "--set-file FILE.json" in _help(("replay",))
    assert "--params" not in _help(("replay",))


# --- the rewriting itself -------------------------------------------------------------------

_SWEEP = (
    OldSpelling("-o", "--set", "--set", applies=looks_like_setting),
    OldSpelling("--override", "--set", "--set"),
    OldSpelling("--out", "--output", "-o/--output"),
)
_SWEEP_OPTIONS = {"--set": True, "-o": True, "--output": True, "-q": False, "--csv": False}


@pytest.mark.parametrize(
    ("argv", "expected", "old"),
    [
        (["s.toml", "-o", "dir"], ["s.toml", "-o", "dir"], []),
        (["s.toml", "--output=dir"], ["s.toml", "--output=dir"], []),
        (["s.toml", "--out", "dir"], ["s.toml", "--output", "dir"], ["--out"]),
        (["s.toml", "--out=dir"], ["s.toml", "--output=dir"], ["--out"]),
        (["-o", "random.draws=5"], ["--set", "random.draws=5"], ["-o"]),
        (["-orandom.draws=5"], ["--set=random.draws=5"], ["-o"]),
        (["-qo", "grid.seed=[1,2]"], ["-q", "--set", "grid.seed=[1,2]"], ["-o"]),
        (["-o", "a.b=1", "-o", "c.d=2"], ["--set", "a.b=1", "--set", "c.d=2"], ["-o"]),
        (["--override", "a.b = 1"], ["--set", "a.b = 1"], ["--override"]),
        (["-o", "sweeps/a.b=1"], ["-o", "sweeps/a.b=1"], []),  # a path, however it reads
        (["--set", "--out"], ["--set", "--out"], []),  # a value stays a value
        (["--", "--out", "x"], ["--", "--out", "x"], []),
        (["--csv", "-", "--out"], ["--csv", "-", "--output"], ["--out"]),
    ],
)
def test_old_spellings_become_new_ones(
    argv: list[str], expected: list[str], old: list[str]
) -> None:
    args, used = modernise(argv, _SWEEP, _SWEEP_OPTIONS)
    assert args == expected
    assert [s.old for s in used] == old


@pytest.mark.parametrize(
    ("value", "setting"),
    [
        ("random.draws=50", True),
        ("grid.seed=[1,2,3]", True),
        (" sweep.timeout_s = 900", True),
        ("scenes.hard.seeds=[1]", True),
        ("sweeps/wind", False),
        ("out", False),
        ("/shared/sweeps/a.b=c", False),
        ("draws=5", False),  # every spec value is in a table
        ("", False),
    ],
)
def test_a_setting_is_told_from_a_folder(value: str, setting: bool) -> None:
    assert looks_like_setting(value) is setting


# --- each command, old and new spelling -------------------------------------------------------


@pytest.fixture(scope="module")
def frame(tmp_path_factory: pytest.TempPathFactory) -> Path:
    small = Intrinsics.from_hfov(width_px=160, height_px=120)
    image = render(load_scene("paper"), CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), small)
    path = tmp_path_factory.mktemp("frame") / "frame.png"
    path.write_bytes(png_encode(image))
    return path


@pytest.mark.parametrize("spelling", ["-o", "--output", "--output=", "--out", "--out="])
def test_vision_vectorize_output(frame: Path, tmp_path: Path, spelling: str) -> None:
    out = tmp_path / "shapes.json"
    argv = [f"{spelling}{out}"] if spelling.endswith("=") else [spelling, str(out)]
    result = _invoke("vision", "vectorize", str(frame), *argv)
    assert result.exit_code == 0, result.output
    assert isinstance(json.loads(out.read_text()), list | dict)
    if spelling.startswith("--out") and not spelling.startswith("--output"):
        assert _warnings(result) == [
            "uavtool: warning: --out is deprecated and goes in the next release; use -o/--output"
        ]
    else:
        assert result.stderr == ""


class _RanError(Exception):
    """What the sweep command asked of the library (the fake run_sweep stops there)."""

    def __init__(self, spec: Any, kwargs: dict[str, Any]) -> None:
        super().__init__("ran")
        self.spec = spec
        self.kwargs = kwargs


@pytest.fixture
def spec(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    def fake(spec: Any, **kwargs: Any) -> None:
        raise _RanError(spec, kwargs)

    monkeypatch.setattr("uavtool.sweep.run_sweep", fake)
    path = tmp_path / "two.toml"
    path.write_text(SPEC)
    return path


def _sweep(*args: str) -> tuple[_RanError, list[str]]:
    result = _invoke("sweep", *args)
    assert isinstance(result.exception, _RanError), result.output
    return result.exception, _warnings(result)


def test_sweep_new_spellings(spec: Path, tmp_path: Path) -> None:
    ran, warnings = _sweep(str(spec), "--set", "grid.seed=[3]", "-o", str(tmp_path / "w"))
    assert warnings == []
    assert ran.kwargs["out"] == tmp_path / "w"
    assert ran.spec.text.endswith("# --set grid.seed=[3]\n")
    ran, _ = _sweep(str(spec), "--output", str(tmp_path / "v"))
    assert ran.kwargs["out"] == tmp_path / "v"


def test_sweep_dash_o_with_a_setting_is_the_old_override(spec: Path, tmp_path: Path) -> None:
    new, _ = _sweep(str(spec), "--set", "grid.seed=[3]", "--set", "random.draws=0")
    old, warnings = _sweep(
        str(spec), "-o", "grid.seed=[3]", "-o", "random.draws=0", "--out", str(tmp_path / "x")
    )
    assert old.spec == new.spec  # both -o values applied, as --set would
    assert old.kwargs["out"] == tmp_path / "x"
    assert warnings == [  # once for the two -o, once for --out
        "uavtool: warning: -o KEY.PATH=VALUE is deprecated and goes in the next release; use "
        "--set KEY.PATH=VALUE (-o now names the output folder)",
        "uavtool: warning: --out is deprecated and goes in the next release; use -o/--output",
    ]


def test_sweep_override_still_works(spec: Path) -> None:
    new, _ = _sweep(str(spec), "--set", "grid.seed=[3]")
    old, warnings = _sweep(str(spec), "--override", "grid.seed=[3]")
    assert old.spec == new.spec
    assert warnings == [
        "uavtool: warning: --override is deprecated and goes in the next release; use "
        "--set KEY.PATH=VALUE"
    ]


def test_sweep_dash_o_with_a_folder_is_the_output(spec: Path, tmp_path: Path) -> None:
    ran, warnings = _sweep(str(spec), "-o", str(tmp_path / "out.d"))
    assert warnings == []
    assert ran.kwargs["out"] == tmp_path / "out.d"
    assert not ran.spec.text.count("# --")


def test_a_bad_setting_through_old_dash_o_is_one_error_line(tmp_path: Path) -> None:
    path = tmp_path / "s.toml"
    path.write_text(SPEC)
    result = _invoke("sweep", str(path), "-o", "grid.seed=[-1]", "-o", str(tmp_path / "o"))
    assert result.exit_code == 2
    errors = [ln for ln in result.stderr.splitlines() if not ln.startswith("uavtool: warning:")]
    assert len(errors) == 1 and "grid.seed[0]: expected a whole number" in errors[0]
    assert not (tmp_path / "o").exists()


def test_sweep_resume_hint_is_the_command_that_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Started with the old spellings, interrupted: the hint spells it the new way, and
    running the hint asks for the same sweep, in the same folder, with --resume."""
    path = tmp_path / "my spec.toml"
    path.write_text(SPEC)
    out = tmp_path / "out folder"
    calls: list[tuple[Any, dict[str, Any]]] = []

    def fake(spec: Any, **kwargs: Any) -> Any:
        calls.append((spec, kwargs))
        root = kwargs["out"]
        return SimpleNamespace(
            summary_text="",
            table=root / "results.parquet",
            plots=(),
            plots_note="",
            interrupted=True,
            rows=(),
            summary=SimpleNamespace(planned=2, errors=0),
        )

    monkeypatch.setattr("uavtool.sweep.run_sweep", fake)
    args = ["sweep", str(path), "-o", "grid.seed=[5, 6]", "--out", str(out), "--timeout", "90"]
    first = _invoke(*args, "--workers", "1", "--csv")
    assert first.exit_code == 130, first.output
    hint = first.stderr.split("continue with: ", 1)[1].strip()
    assert hint == shlex.join(
        [
            *["uavtool", "sweep", str(path), "--set", "grid.seed=[5, 6]", "--output", str(out)],
            *["--timeout", "90", "--workers", "1", "--csv", "--resume"],
        ]
    )
    again = _invoke(*shlex.split(hint)[1:])
    assert again.exit_code == 130 and _warnings(again) == []
    (spec_1, kw_1), (spec_2, kw_2) = calls
    assert spec_2 == spec_1
    assert kw_2 == {**kw_1, "resume": True, "progress": kw_2["progress"]}


def test_replay_set_file_and_old_params(tmp_path: Path) -> None:
    missing = tmp_path / "nope.json"
    new = _invoke("replay", str(PAPER), "--set-file", str(missing))
    old = _invoke("replay", str(PAPER), "--params", str(missing))
    for result in (new, old):
        assert _one_error(result).startswith(f"--set-file {missing}: cannot read")
    assert _warnings(new) == []
    assert _warnings(old) == [
        "uavtool: warning: --params is deprecated and goes in the next release; use --set-file"
    ]


def test_replay_output_old_and_new(tmp_path: Path) -> None:
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"recognize": {"threshold": 0.9}}))
    for spelling in ("-o", "--out"):
        out = tmp_path / f"replayed{spelling}.mcap"
        result = _invoke("replay", "-q", str(PAPER), "--set-file", str(params), spelling, str(out))
        assert result.exit_code == 0, result.output
        assert out.is_file()
        assert len(_warnings(result)) == (spelling == "--out")


def test_fly_output_and_old_record(tmp_path: Path) -> None:
    new = _invoke("fly", "-q", "-o", str(tmp_path / "a.mcap"))
    old = _invoke("fly", "-q", "--record", str(tmp_path / "b.mcap"))
    assert new.exit_code == old.exit_code == 0, new.output + old.output
    assert (tmp_path / "a.mcap").is_file() and (tmp_path / "b.mcap").is_file()
    assert _warnings(new) == []
    assert _warnings(old) == [
        "uavtool: warning: --record is deprecated and goes in the next release; use -o/--output"
    ]


def test_fly_output_and_no_record_exclude_each_other(tmp_path: Path) -> None:
    result = _invoke("fly", "-o", str(tmp_path / "a.mcap"), "--no-record")
    assert result.exit_code == 2
    assert result.stderr == "uavtool: error: -o/--output and --no-record exclude each other\n"


# --- the web viewer's ports ---------------------------------------------------------------------

_WEB = {"view": ["view", str(PAPER), "--web"], "fly": ["fly", "--no-record", "--rerun", "web"]}


@pytest.mark.parametrize("command", _WEB)
@pytest.mark.parametrize("option", ["--web-port", "--grpc-port"])
@pytest.mark.parametrize("port", ["0", "65536", "-1", "http", "80.5"])
def test_a_port_is_1_to_65535(command: str, option: str, port: str) -> None:
    message = _one_error(_invoke(*_WEB[command], option, port))
    assert message == f"{option}={port}: expected an integer in [1, 65535]"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["view", "x.mcap", "--web-port", "8080"], "--web-port goes with --web"),
        (["view", "x.mcap", "--grpc-port", "8081", "--save", "x.rrd"], "--grpc-port goes with"),
        (["fly", "--web-port", "8080"], "--web-port goes with --rerun web"),
        (["fly", "--rerun", "x.rrd", "--grpc-port", "8081"], "--grpc-port goes with --rerun web"),
        (["view", str(PAPER), "--web", "--web-port", "8080", "--grpc-port", "8080"], "both"),
        (["fly", "--rerun", "web", "--grpc-port", "9090"], "both"),  # the default web port
    ],
)
def test_port_options_that_cannot_work(argv: list[str], message: str) -> None:
    assert message in _one_error(_invoke(*argv))


@pytest.fixture
def busy_port() -> Iterator[int]:
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        yield listener.getsockname()[1]


@pytest.mark.parametrize("command", _WEB)
@pytest.mark.parametrize("option", ["--web-port", "--grpc-port"])
def test_a_busy_port_is_one_line(command: str, option: str, busy_port: int) -> None:
    message = _one_error(_invoke(*_WEB[command], option, str(busy_port)))
    assert message == (
        f"{option} {busy_port}: already in use on 127.0.0.1 (another viewer?); choose another "
        "port, or stop what holds it"
    )


def test_view_old_port_option(busy_port: int) -> None:
    result = _invoke("view", str(PAPER), "--web", "--port", str(busy_port))
    assert _one_error(result).startswith(f"--web-port {busy_port}: already in use")
    assert _warnings(result) == [
        "uavtool: warning: --port is deprecated and goes in the next release; use --web-port"
    ]
