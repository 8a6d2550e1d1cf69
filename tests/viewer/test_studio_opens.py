"""Every channel of every golden recording opens in Foxglove Studio's (and so Lichtblick's)
MCAP source with no problem, and what its panels need is there: images, a plottable
``/mavlink/in/ATTITUDE.roll``, the log, and a 3D scene (route, photo poses, model); a fleet's
(``fleet-search``) has every topic its ``export --layout`` names."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.viewer.studio import assets, open_in_studio
from uavtool.cli import cli
from uavtool.recording import summarize
from uavtool.recording.foxglove_layout import layout_for

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


def test_every_topic_a_fleets_layout_names_opens(bundle: Path) -> None:
    """(That every channel of the fleet's golden opens: `test_every_channel_opens`.)"""
    fleet = next(p for p in GOLDEN if p.stem == "fleet-search")
    seen = open_in_studio(bundle, fleet)
    decoded = {t: v["decoded"] for t, v in seen["perTopic"].items()}
    config = layout_for(fleet)["configById"]
    named = {t for c in config.values() for t in (*c.get("topics", {}), *c.get("topicColors", {}))}
    named |= {c["imageMode"]["imageTopic"] for c in config.values() if "imageMode" in c}
    named |= {c["topicToRender"] for c in config.values() if "topicToRender" in c}
    for panel in ("Plot!height", "Plot!attitude", "StateTransitions!modes"):
        named |= {line["value"].split("{")[0].split(".")[0] for line in config[panel]["paths"]}
    # Each vehicle's scene, pose, camera, log, fix and observations; the model, the target and
    # the shared ATTITUDE.
    assert len(named) == 3 * 6 + 3
    assert all(decoded.get(t, 0) > 0 for t in named), {t: decoded.get(t) for t in named}
    first = {t: v["first"] for t, v in seen["perTopic"].items()}
    # The fields the plots' paths walk, as the app decodes them.
    assert isinstance(first["/uav1/vehicle/pose"]["poses"][0]["position"]["z"], float | int)
    assert isinstance(first["/mavlink/in/ATTITUDE"]["header"]["sysid"], int)
    assert isinstance(first["/mavlink/in/ATTITUDE"]["roll"], float | int)
    assert {"latitude", "longitude"} <= set(first["/uav2/vehicle/fix"])
