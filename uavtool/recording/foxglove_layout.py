"""``uavtool export REC --layout FILE``: a Foxglove / Lichtblick layout fitted to a recording.

Their 3D panel draws a topic only once it is switched on, and opens looking at the origin from
20 m. The layout switches on the recording's 3D topics (the route, photo poses, points of
interest and viewpoints on ``/mission/scene``, the model, the vehicle's pose) and aims the
camera at the middle of the flown path from a distance that fits all of it in view; next to it
are the camera image, the target picture, a plot of the attitude and the event log. A fleet's
recording (its vehicles' topics under ``/uavK``) gets the fleet's layout
(`uavtool.recording.foxglove_fleet`). The JSON is the layout format both apps import
(Layouts → Import) and that Lichtblick's web image takes as its default layout.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from uavtool.recording.errors import RecordingError
from uavtool.recording.files import atomic_output
from uavtool.recording.fleet import split_topic
from uavtool.recording.foxglove_fleet import fleet_layout
from uavtool.recording.foxglove_panels import image, log, pair, plot, series, split, three_d
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import (
    EVENTS,
    IMAGE,
    MODEL,
    POSE,
    SCENE,
    TARGET,
    VEHICLE_EVENTS,
)
from uavtool.recording.values import PosesInFrame

_PLOT = ("/mavlink/in/ATTITUDE.roll", "/mavlink/in/ATTITUDE.pitch")


def layout_for(rec: str | Path) -> dict[str, Any]:
    """The layout for ``rec``: its topics, and a 3D view that frames its flown path (a
    fleet's: each vehicle's, and a map of them all)."""
    with RecordingReader(rec) as reader:
        topics = set(reader.topics())
        vehicles = sorted({k for k, _ in map(split_topic, topics) if k is not None})
        if vehicles:
            return fleet_layout(reader, topics, vehicles)
        points = [
            p.position_m
            for entry in (reader.entries([POSE]) if POSE in topics else ())
            if isinstance(entry.value, PosesInFrame)
            for p in entry.value.poses
        ]
    shown = [t for t in (SCENE, MODEL, POSE) if t in topics]
    config: dict[str, Any] = {"3D!uavtool": three_d(shown, POSE, points)}
    panels: list[str] = []
    if IMAGE in topics:
        config["Image!camera"] = image(IMAGE)
        panels.append("Image!camera")
    if TARGET in topics:
        config["Image!target"] = image(TARGET)
        panels.append("Image!target")
    plotted = [p for p in _PLOT if p.split(".")[0] in topics]
    if plotted:
        config["Plot!attitude"] = plot([series(p) for p in plotted])
    events = EVENTS if EVENTS in topics else VEHICLE_EVENTS if VEHICLE_EVENTS in topics else None
    if events is not None:
        config["RosOut!events"] = log(events)
    rows = [
        split(panels, "row"),
        "Plot!attitude" if plotted else None,
        "RosOut!events" if events is not None else None,
    ]
    right = split([r for r in rows if r is not None], "column")
    return {
        "configById": config,
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": "3D!uavtool" if right is None else pair("3D!uavtool", right, "row", 55),
    }


def export_layout(rec: str | Path, out: str | Path) -> dict[str, Any]:
    """Write `layout_for` ``rec`` to ``out`` (whole, or not at all) and return it."""
    layout = layout_for(rec)
    with atomic_output(out, inputs=[rec]) as tmp:
        try:
            tmp.write_text(json.dumps(layout, indent=2) + "\n")
        except OSError as exc:
            raise RecordingError(out, f"cannot write: {exc.strerror or exc}") from None
    return layout
