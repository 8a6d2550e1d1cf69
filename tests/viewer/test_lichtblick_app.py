"""Every golden recording opened in Lichtblick's own web app, in headless Chromium, with the
layout ``uavtool export --layout`` writes: no problem reported for any channel (no alert but
informational ones: Lichtblick advises preloading whenever a recording has transforms), no
console error, and each panel shows the recording's data — the last camera frame and the target
picture as recorded (compared pixel by pixel, `shown_image`: another frame fails), a plotted
``ATTITUDE.roll``, the last mission event in the log, and in 3D the route, the photo poses and
the model. A fleet's golden opens with its layout too: the first vehicle's tab (its camera's
last frame and its last event), the target, each vehicle's height in the plot and its row of
flight modes.

Lichtblick publishes its app on no registry, so this runs when ``UAVTOOL_LICHTBLICK`` names a
checkout of its repository (the app is built from it on first use, `lichtblick_app`) and
Chromium is installed; it is skipped otherwise (CI reaches package registries only)."""

from __future__ import annotations

import json
import shutil
from datetime import UTC, datetime
from pathlib import Path

import cv2
import numpy as np
import pytest

from tests.viewer.lichtblick import checkout
from tests.viewer.lichtblick_app import LichtblickApp, build_app, has_app
from tests.viewer.shown_image import MAX_ERROR, shown_error
from uavtool.recording.foxglove_layout import export_layout
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import EVENTS, IMAGE, MODEL, TARGET
from uavtool.recording.values import CompressedImage, LogEntry
from uavtool.replay.load import is_fleet

EVERY_GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))
GOLDEN = [p for p in EVERY_GOLDEN if not is_fleet(p)]
FLEETS = [p for p in EVERY_GOLDEN if is_fleet(p)]
_ROUTE_RGB = (255, 140, 0)  # uavtool.runner.markers: the route's colour
_SERIES_RGB = (78, 152, 226)  # the colour of a Lichtblick plot's first series


@pytest.fixture(scope="module")
def app() -> LichtblickApp:
    repo = checkout()
    if repo is None or not has_app(repo):
        pytest.skip("UAVTOOL_LICHTBLICK does not name a checkout of Lichtblick's repository")
    if not (shutil.which("node") and shutil.which("npm") and Path("/usr/bin/chromium").exists()):
        pytest.skip("node, npm or Debian's chromium not installed")
    return build_app(repo)


def _recorded(recording: Path, prefix: str = "") -> tuple[str, bytes, bytes, str]:
    """The time the app is seeked to (the last message's), the last camera frame, the target
    picture and the last mission event's text (a fleet's: vehicle ``prefix``'s, ``/uav1``)."""
    frames: dict[str, bytes] = {}
    event = ""
    with RecordingReader(recording) as reader:
        end_ns = reader.time_range_ns[1]
        for entry in reader.entries([prefix + IMAGE, TARGET, prefix + EVENTS]):
            if isinstance(entry.value, CompressedImage):
                frames[entry.topic] = entry.value.data
            elif isinstance(entry.value, LogEntry):
                event = entry.value.message
    seconds, nanos = divmod(end_ns, 1_000_000_000)
    time = f"{datetime.fromtimestamp(seconds, UTC):%Y-%m-%dT%H:%M:%S}.{nanos:09d}Z"
    return time, frames[prefix + IMAGE], frames[TARGET], event


def _rgb(png: Path | bytes) -> np.ndarray:
    data = np.frombuffer(png.read_bytes() if isinstance(png, Path) else png, np.uint8)
    return np.asarray(cv2.imdecode(data, cv2.IMREAD_COLOR)[:, :, ::-1], dtype=np.int32)


def _near(panel: np.ndarray, rgb: tuple[int, int, int]) -> int:
    return int((np.abs(panel - np.array(rgb)).sum(axis=-1) < 60).sum())


@pytest.mark.parametrize("recording", GOLDEN, ids=[p.stem for p in GOLDEN])
def test_lichtblick_shows_every_channel_of_the_golden(
    app: LichtblickApp, recording: Path, tmp_path: Path
) -> None:
    time, frame, target, event = _recorded(recording)
    layout = tmp_path / "layout.json"
    export_layout(recording, layout)
    seen = app.open(recording, layout, time, tmp_path / "shown")
    shown = tmp_path / "shown"

    assert seen["errors"] == []
    # The tab's badge has the colour of its most severe alert (none: no badge).
    assert seen["severity"] in (None, "Info"), f"{seen['badge']} alerts: {seen['problems']}"
    for panel, picture in (("Image!camera", frame), ("Image!target", target)):
        png = shown / f"{panel.replace('!', '_')}.png"
        error = shown_error(_rgb(png), seen["canvases"][panel], _rgb(picture))
        assert error < MAX_ERROR, f"{panel} differs from the recorded picture by {error:.2f}"
    legend = seen["panels"]["Plot!attitude"].split("\n")
    roll = legend[legend.index("/mavlink/in/ATTITUDE.roll") + 1]
    assert np.isfinite(float(roll))  # the legend's value at the playhead: a number
    assert _near(_rgb(shown / "Plot_attitude.png"), _SERIES_RGB) > 200  # the roll line
    assert event and event in seen["panels"]["RosOut!events"].replace("\xa0", " ")
    three_d = _rgb(shown / "3D_uavtool.png")
    assert _near(three_d, _ROUTE_RGB) > 300

    with RecordingReader(recording) as reader:
        has_model = MODEL in reader.topics()
    if has_model:  # the model draws: hiding its topic changes the 3D view
        hidden = json.loads(layout.read_text())
        hidden["configById"]["3D!uavtool"]["topics"][MODEL]["visible"] = False
        layout.write_text(json.dumps(hidden))
        app.open(recording, layout, time, tmp_path / "no-model")
        without = _rgb(tmp_path / "no-model" / "3D_uavtool.png")
        assert (np.abs(three_d - without).sum(axis=-1) > 30).sum() > 500


@pytest.mark.parametrize("recording", FLEETS, ids=[p.stem for p in FLEETS])
def test_lichtblick_shows_every_vehicle_of_a_fleet(
    app: LichtblickApp, recording: Path, tmp_path: Path
) -> None:
    time, frame, target, event = _recorded(recording, "/uav1")
    layout = tmp_path / "layout.json"
    config = export_layout(recording, layout)["configById"]
    seen = app.open(recording, layout, time, tmp_path / "shown")
    shown = tmp_path / "shown"

    # The map's tiles come from OpenStreetMap's servers: offline, each one fails to load.
    assert [e for e in seen["errors"] if not e.startswith("Failed to load resource")] == []
    assert seen["severity"] in (None, "Info"), f"{seen['badge']} alerts: {seen['problems']}"
    assert "map!fleet" in seen["panels"]
    # The first vehicle's tab is the one open.
    for panel, picture in (("Image!uav1", frame), ("Image!target", target)):
        png = shown / f"{panel.replace('!', '_')}.png"
        error = shown_error(_rgb(png), seen["canvases"][panel], _rgb(picture))
        assert error < MAX_ERROR, f"{panel} differs from the recorded picture by {error:.2f}"
    assert event and event in seen["panels"]["RosOut!uav1"].replace("\xa0", " ")
    legend = seen["panels"]["Plot!height"].split("\n")
    modes = seen["panels"]["StateTransitions!modes"]
    for line in config["Plot!height"]["paths"]:
        height = legend[legend.index(line["label"]) + 1]
        assert np.isfinite(float(height))  # the legend's value at the playhead: a number
        assert line["label"].replace("height (m)", "mode") in modes
