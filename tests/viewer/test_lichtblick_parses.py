"""Every channel and message of every golden recording goes through Lichtblick's own MCAP
parsing code (``packages/mcap-support``: ``parseChannel``, its JSON-schema and Protobuf
parsers and deserializers) with no problem. Lichtblick publishes that code on no registry,
so this runs when ``UAVTOOL_LICHTBLICK`` names a checkout of its repository, and is skipped
otherwise (CI reaches package registries only)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.viewer.lichtblick import build, checkout, parse

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


@pytest.fixture(scope="module")
def bundle() -> Path:
    repo = checkout()
    if repo is None:
        pytest.skip("UAVTOOL_LICHTBLICK does not name a checkout of Lichtblick's repository")
    if shutil.which("node") is None or shutil.which("npm") is None:
        pytest.skip("node/npm not installed")
    return build(repo)


@pytest.mark.parametrize("recording", GOLDEN, ids=[p.stem for p in GOLDEN])
def test_lichtblick_parses_every_channel_and_message(bundle: Path, recording: Path) -> None:
    seen = parse(bundle, recording)
    assert seen["problems"] == {}
    assert seen["channelsParsed"] == seen["channels"] >= 30
    assert seen["ok"] == seen["total"] > 20_000
    assert isinstance(seen["attitudeRoll"], int | float)  # plottable: a number
