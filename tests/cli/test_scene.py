"""The `uavtool scene` commands, run through click."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.world import load_scene, render


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_list_names_every_builtin_scene() -> None:
    code, out, _ = _run("scene", "list")
    assert code == 0
    for name in ("paper", "dense", "blocked-front"):
        assert name in out


def test_render_writes_the_library_frame_losslessly(tmp_path: Path) -> None:
    out = tmp_path / "front.png"
    code, _, err = _run(
        "scene", "render", "paper", "--pos", "10,-32,3", "--yaw", "0", "--pitch", "0",
        "--size", "320x240", "--fov", "70", "-o", str(out),
    )  # fmt: skip
    assert code == 0, err
    written = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)[:, :, ::-1]
    expected = render(
        load_scene("paper"),
        CameraPose((10.0, -32.0, 3.0), 0.0, 0.0),
        Intrinsics.from_hfov(width_px=320, height_px=240, hfov_deg=70.0),
    )
    assert np.array_equal(written, expected)


def test_show_and_random_and_validate(tmp_path: Path) -> None:
    code, _, err = _run(
        "scene", "show", "dense", "--size", "320x240", "-o", str(tmp_path / "d.png")
    )
    assert code == 0, err
    assert cv2.imread(str(tmp_path / "d.png")).shape == (240, 320, 3)
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    assert _run("scene", "random", "--seed", "5", "--buildings", "6", "-o", str(a))[0] == 0
    assert _run("scene", "random", "--seed", "5", "--buildings", "6", "-o", str(b))[0] == 0
    assert a.read_bytes() == b.read_bytes()
    code, out, _ = _run("scene", "validate", str(a))
    assert code == 0
    assert "ok: 6 buildings" in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("scene", "render", "paper", "--pos", "1,2", "-o", "x.png"), "--pos=1,2: expected E,N,U"),
        (
            ("scene", "render", "paper", "--pos", "0,0,45", "--size", "big", "-o", "x.png"),
            "--size 'big'",
        ),
        (
            ("scene", "render", "paper", "--pos", "0,0,45", "--fov", "0", "-o", "x.png"),
            "--fov=0: expected a finite number in [1, 170]",
        ),
        (
            ("scene", "render", "paper", "--pos", "0,0,45", "--pitch", "120", "-o", "x.png"),
            "--pitch=120: expected a finite number in [-90, 90]",
        ),
        (("scene", "render", "paper", "--pos", "0,0,45", "-o", "x.jpg"), "output must be a .png"),
        (
            ("scene", "render", "nowhere.yaml", "--pos", "0,0,45", "-o", "x.png"),
            "no such scene file",
        ),
        (
            ("scene", "random", "--seed", "1", "--buildings", "0", "-o", "x.yaml"),
            "--buildings=0: expected an integer ≥ 1",
        ),
        (("scene", "validate", "BAD"), "BAD.yaml:3: buildings[0].color: expected [r, g, b]"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    args: tuple[str, ...], message: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "BAD.yaml").write_text(
        "target: a\nbuildings:\n  - {name: a, color: [1, 2], blocks: []}\n"
    )
    args = tuple("BAD.yaml" if a == "BAD" else a for a in args)
    code, _, err = _run(*args)
    assert code == 2
    assert message in err
    assert err.startswith("uavtool: error: ")
    assert err.count("\n") == 1


@pytest.mark.parametrize("command", ["list", "validate", "render", "show", "random"])
def test_every_command_has_an_example(command: str) -> None:
    code, out, _ = _run("scene", command, "--help")
    assert code == 0
    assert "Example" in out
    assert f"uavtool scene {command}" in out
