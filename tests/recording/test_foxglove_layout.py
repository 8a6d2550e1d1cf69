"""``uavtool export REC --layout FILE``: a Foxglove / Lichtblick layout that shows the
recording. (That Lichtblick itself draws every panel of it is `tests/viewer`'s part.)"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from click.testing import CliRunner

from tests.recording.sample import write_sample
from uavtool.cli import cli
from uavtool.recording.foxglove_layout import layout_for
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import EVENTS, IMAGE, MODEL, POSE, SCENE, TARGET
from uavtool.recording.values import PosesInFrame

PAPER = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def _placed(node: Any) -> list[str]:
    """The panel ids a mosaic layout tree places."""
    if isinstance(node, str):
        return [node]
    return _placed(node["first"]) + _placed(node["second"])


def test_the_layout_of_a_flight_shows_its_route_model_images_plot_and_log() -> None:
    layout = layout_for(PAPER)
    config = layout["configById"]
    assert sorted(_placed(layout["layout"])) == sorted(config)
    three_d = config["3D!uavtool"]
    assert {t for t, s in three_d["topics"].items() if s["visible"]} == {SCENE, MODEL, POSE}
    assert config["Image!camera"]["imageMode"]["imageTopic"] == IMAGE
    assert config["Image!target"]["imageMode"]["imageTopic"] == TARGET
    plotted = [p["value"] for p in config["Plot!attitude"]["paths"]]
    assert "/mavlink/in/ATTITUDE.roll" in plotted
    assert config["RosOut!events"]["topicToRender"] == EVENTS


def test_the_3d_view_holds_every_pose_the_vehicle_flew() -> None:
    camera = layout_for(PAPER)["configById"]["3D!uavtool"]["cameraState"]
    with RecordingReader(PAPER) as reader:
        points = [
            p.position_m
            for e in reader.entries([POSE])
            if isinstance(e.value, PosesInFrame)
            for p in e.value.poses
        ]
    centre, distance = camera["targetOffset"], camera["distance"]
    half_fov = math.radians(camera["fovy"] / 2)
    # Seen from `distance`, a point within this radius of the centre is within the half field
    # of view in every direction the camera might look from.
    assert max(math.dist(p, centre) for p in points) < distance * math.sin(half_fov)
    assert max(math.dist(p, centre) for p in points) > 0.5 * distance * math.sin(half_fov)


def test_export_writes_a_layout_for_a_recording_without_a_mission(tmp_path: Path) -> None:
    rec, out = tmp_path / "rec.mcap", tmp_path / "rec.layout.json"
    write_sample(rec, seconds=1.0)
    result = CliRunner().invoke(cli, ["export", str(rec), "--layout", str(out)])
    assert result.exit_code == 0, result.output
    layout = json.loads(out.read_text())
    assert "wrote a layout of" in result.output and str(out) in result.output
    assert sorted(_placed(layout["layout"])) == sorted(layout["configById"])
    assert "Image!target" not in layout["configById"]


def test_export_never_writes_over_the_recording_nor_leaves_a_traceback(tmp_path: Path) -> None:
    rec = tmp_path / "rec.mcap"
    write_sample(rec, seconds=1.0)
    before = rec.read_bytes()
    result = CliRunner().invoke(cli, ["export", str(rec), "--layout", str(rec)])
    assert result.exit_code == 2, result.output
    assert rec.read_bytes() == before
    nowhere = tmp_path / "no" / "such" / "folder" / "layout.json"
    result = CliRunner().invoke(cli, ["export", str(rec), "--layout", str(nowhere)])
    assert result.exit_code == 2, result.output
    assert result.output.strip().splitlines() == [
        f"uavtool: error: {nowhere}: cannot write: No such file or directory"
    ]
