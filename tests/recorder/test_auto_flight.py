"""`uavtool record --camera sim` records an AUTO mission that a scripted ground station flies
on the built-in vehicle: the whole flight, photos at the right poses, nothing sent; then the
recording is analysed offline (replay --vision-only, view --save, export --frames)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tests.recorder.flight import PHOTO_ALT_M, STOPS, Recorded
from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.images import png_decode
from uavtool.recording import CompressedImage, Direction, JsonDocument, LogEntry, RecordingReader
from uavtool.recording.topics import FRAMES, IMAGE, TELEMETRY, VEHICLE_EVENTS
from uavtool.runner.fly import target_picture
from uavtool.world import load_scene, render


def _read(path: Path) -> tuple[list[dict], list[tuple[dict, bytes]], list[str], int]:
    telemetry, frames, events, images, out_frames = [], [], [], [], 0
    with RecordingReader(path) as reader:
        assert reader.health.whole
        for e in reader.entries([TELEMETRY, FRAMES, IMAGE, VEHICLE_EVENTS, "/mavlink/raw"]):
            v = e.value
            if e.topic == TELEMETRY and isinstance(v, JsonDocument):
                telemetry.append(dict(v.payload))
            elif e.topic == FRAMES and isinstance(v, JsonDocument):
                frames.append(dict(v.payload))
            elif isinstance(v, CompressedImage):
                images.append(v.data)
            elif isinstance(v, LogEntry):
                events.append(v.message)
            elif getattr(v, "direction", None) == Direction.OUT:
                out_frames += 1
    return telemetry, [(f, images[f["frame_index"]]) for f in frames], events, out_frames


def test_the_whole_flight_is_recorded_and_nothing_is_sent(recorded: Recorded) -> None:
    telemetry, frames, events, out_frames = _read(recorded.path)
    assert "(landed)" in recorded.stdout
    assert out_frames == 0 and recorded.sent_to_vehicle == 0  # passive: on file and on the link
    assert not telemetry[0]["armed"] and telemetry[0]["landed"]  # from before take-off …
    assert max(t["pos_enu_m"][2] for t in telemetry) == pytest.approx(PHOTO_ALT_M, abs=0.5)
    assert not telemetry[-1]["armed"] and telemetry[-1]["pos_enu_m"][2] < 0.1  # … to the end
    assert {"mode GUIDED → AUTO", "armed", "disarmed"} <= set(events)
    assert any(e.startswith("mission: reached item") for e in events)
    assert len([f for f, _ in frames if f["photo"] >= 0]) == len(STOPS)
    assert any(f["photo"] < 0 for f, _ in frames)  # plain frames at --rate between photos


def test_photos_are_taken_above_each_building_and_show_the_recorded_pose(
    recorded: Recorded,
) -> None:
    scene = load_scene("paper")
    _, frames, _, _ = _read(recorded.path)
    photos = [(f, png) for f, png in frames if f["photo"] >= 0]
    for (record, png), (east, north) in zip(photos, STOPS.values(), strict=True):
        x, y, z = record["pose"]["pos_enu_m"]
        assert math.hypot(x - east, y - north) < 1.0 and z == pytest.approx(PHOTO_ALT_M, abs=0.5)
        assert record["pose"]["pitch_deg"] == pytest.approx(-90.0, abs=0.5)
        assert record["trigger"] == "CAMERA_FEEDBACK" and record["pose_dt_ms"] == 0
        pose = CameraPose((x, y, z), record["pose"]["heading_deg"], record["pose"]["pitch_deg"])
        k = record["intrinsics"]
        intrinsics = Intrinsics.from_hfov(width_px=k["width_px"], height_px=k["height_px"])
        assert np.array_equal(png_decode(png, where="photo"), render(scene, pose, intrinsics))


def test_vision_only_finds_the_red_building_and_view_shows_it(
    recorded: Recorded, tmp_path: Path
) -> None:
    scene = load_scene("paper")
    target = tmp_path / "target.png"
    target.write_bytes(target_picture(scene, Intrinsics.from_hfov()))
    analysed = tmp_path / "analysed.mcap"
    runner = CliRunner()
    args = ["replay", "--vision-only", str(recorded.path), "--target", str(target)]
    result = runner.invoke(cli, [*args, "--output", str(analysed)])
    assert result.exit_code == 0, result.output
    _, frames, _, _ = _read(recorded.path)
    red = [f["frame_index"] for f, _ in frames if f["photo"] == list(STOPS).index("red")]
    assert f"1 match: frames {red[0]}" in result.output, result.output

    saved = tmp_path / "analysed.rrd"
    result = runner.invoke(cli, ["view", str(analysed), "--save", str(saved)])
    assert result.exit_code == 0, result.output
    assert f"{len(frames)} frames" in result.output and "4 recognitions" in result.output
    assert saved.stat().st_size > 0

    out = tmp_path / "frames"
    result = runner.invoke(cli, ["export", str(analysed), "--frames", str(out)])
    assert result.exit_code == 0, result.output
    sidecar = json.loads((out / f"frame_{red[0]:04d}.json").read_text())
    assert sidecar["tag"] == f"photo-{list(STOPS).index('red')}"
    assert (out / f"frame_{red[0]:04d}.png").read_bytes() == frames[red[0]][1]
    assert (out / "target.png").read_bytes() == target.read_bytes()

    layout = tmp_path / "layout.json"
    result = runner.invoke(cli, ["export", str(recorded.path), "--layout", str(layout)])
    assert result.exit_code == 0, result.output
    config = json.loads(layout.read_text())["configById"]
    assert config["RosOut!events"]["topicToRender"] == VEHICLE_EVENTS
    assert config["Image!camera"]["imageMode"]["imageTopic"] == IMAGE
