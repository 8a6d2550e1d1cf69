"""Every command, fed a corpus of bad inputs, answers with one line and exit code 2.

The corpus (``bad_inputs.py``): malformed and hostile scene files (an alias bomb, deep
nesting, huge numbers, 100k vertices, 10k buildings, duplicate keys), images (empty,
corrupt, headers claiming 100000×100000 pixels), ``--set`` and option values (NaN, ∞,
negative, wrong types, out of range) and recordings (not MCAP, empty, truncated, missing).
A traceback, another exit code or a message on more than one line fails the case.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.cli import bad_inputs
from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.images import png_encode
from uavtool.world import load_scene, render

CASES = bad_inputs.cases()


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("bad-inputs")
    bad_inputs.write_files(folder)
    small = Intrinsics.from_hfov(width_px=160, height_px=120)
    frame = render(load_scene("paper"), CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), small)
    (folder / "good.png").write_bytes(png_encode(frame))
    return folder


@pytest.mark.parametrize("case", [pytest.param(c, id=c.name, marks=c.marks) for c in CASES])
def test_bad_input_gets_one_line_and_exit_2(case: bad_inputs.Case, root: Path) -> None:
    argv = [arg.replace(bad_inputs.ROOT, str(root)) for arg in case.argv]
    result = CliRunner().invoke(cli, argv)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert "Traceback" not in result.stderr + result.stdout
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 2, result.stderr
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("uavtool: error: "), result.stderr


def test_corpus_counts() -> None:
    counts = Counter(c.kind for c in CASES)
    print(f"bad-input corpus: {len(CASES)} command lines: {dict(sorted(counts.items()))}")
    assert counts["scene"] >= 90 and counts["image"] >= 30 and counts["value"] >= 60
    assert counts["recording"] >= 20
