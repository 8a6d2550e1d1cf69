"""Every channel of every golden recording opens in Foxglove Studio's (and so Lichtblick's)
MCAP source with no problem, and what its panels need is there: images, a plottable
``/mavlink/in/ATTITUDE.roll``, the log, and a 3D scene (route, photo poses, model)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.viewer.studio import assets, open_in_studio
from uavtool.cli import cli
from uavtool.recording import summarize

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


@pytest.fixture(scope="module")
def bundle() -> Path:
    found = assets()
    if found is None:
        if os.environ.get("CI"):
            pytest.fail("node and npm are needed to check recordings in Foxglove/Lichtblick")
        pytest.skip("node/npm not installed")
    return found


@pytest.mark.parametrize("recording", GOLDEN, ids=[p.stem for p in GOLDEN])
def test_every_channel_opens(bundle: Path, recording: Path) -> None:
    seen = open_in_studio(bundle, recording)
    assert seen["problems"] == []
    counts = {t.topic: t.count for t in summarize(recording).topics}
    decoded = {t: v["decoded"] for t, v in seen["perTopic"].items()}
    assert decoded == counts  # every message of every topic, decoded by the app


def test_panels_have_data(bundle: Path) -> None:
    paper = next(p for p in GOLDEN if p.stem == "paper")
    first = {t: v["first"] for t, v in open_in_studio(bundle, paper)["perTopic"].items()}
    image = first["/camera/image"]
    assert image["format"] == "png"
    assert image["data"]["bytes"] > 1000
    assert isinstance(first["/mavlink/in/ATTITUDE"]["roll"], float | int)
    assert first["/mission/events"]["message"]
    assert first["/mission/observations"]["type"]
    entities = {e["id"]: e for e in first["/mission/scene"]["entities"]}
    assert entities["route"]["lines"]
    assert "photos" in entities
    assert first["/mission/model"]["entities"][0]["models"][0]["data"]["bytes"] > 0
    assert first["/mavlink/raw"]["frame"]["bytes"] > 0


def test_detections_and_pictures_open(bundle: Path, tmp_path: Path) -> None:
    """What users add: a vision function's detections (``replay --vision``) and a mission's
    pictures and results (the survey's mosaic) open with no problem, every message decoded."""
    paper = next(p for p in GOLDEN if p.stem == "paper")
    detected, survey = tmp_path / "detected.mcap", tmp_path / "survey.mcap"
    runs = [
        ["replay", str(paper), "--vision", "tests.plugins.detector:red_roofs", "--output",
         str(detected)],
        ["fly", "-q", "--mission", "survey", "--output", str(survey)],
    ]  # fmt: skip
    for args in runs:
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 0, result.output
    for recording in (detected, survey):
        seen = open_in_studio(bundle, recording)
        assert seen["problems"] == [], recording.name
        counts = {t.topic: t.count for t in summarize(recording).topics}
        assert {t: v["decoded"] for t, v in seen["perTopic"].items()} == counts
    first = open_in_studio(bundle, detected)["perTopic"]["/vision/annotations"]["first"]
    assert "points" in first and "texts" in first
