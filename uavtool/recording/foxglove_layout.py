"""``uavtool export REC --layout FILE``: a Foxglove / Lichtblick layout fitted to a recording.

Their 3D panel draws a topic only once it is switched on, and opens looking at the origin from
20 m. The layout switches on the recording's 3D topics (the route, photo poses, points of
interest and viewpoints on ``/mission/scene``, the model, the vehicle's pose) and aims the
camera at the middle of the flown path from a distance that fits all of it in view; next to it
are the camera image, the target picture, a plot of the attitude and the event log. The JSON is
the layout format both apps import (Layouts → Import) and that Lichtblick's web image takes as
its default layout.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from uavtool.recording.errors import RecordingError
from uavtool.recording.files import atomic_output
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

_FOVY_DEG = 45.0  # the 3D panel's default vertical field of view
_PLOT = ("/mavlink/in/ATTITUDE.roll", "/mavlink/in/ATTITUDE.pitch")


def layout_for(rec: str | Path) -> dict[str, Any]:
    """The layout for ``rec``: its topics, and a 3D view that frames its flown path."""
    with RecordingReader(rec) as reader:
        topics = set(reader.topics())
        points = [
            p.position_m
            for entry in (reader.entries([POSE]) if POSE in topics else ())
            if isinstance(entry.value, PosesInFrame)
            for p in entry.value.poses
        ]
    config: dict[str, Any] = {"3D!uavtool": _three_d(topics, points)}
    panels: list[str] = []
    if IMAGE in topics:
        config["Image!camera"] = {"imageMode": {"imageTopic": IMAGE}}
        panels.append("Image!camera")
    if TARGET in topics:
        config["Image!target"] = {"imageMode": {"imageTopic": TARGET}}
        panels.append("Image!target")
    plotted = [p for p in _PLOT if p.split(".")[0] in topics]
    if plotted:
        config["Plot!attitude"] = _plot(plotted)
    log = EVENTS if EVENTS in topics else VEHICLE_EVENTS if VEHICLE_EVENTS in topics else None
    if log is not None:
        config["RosOut!events"] = {"topicToRender": log, "searchTerms": [], "minLogLevel": 1}
    rows = [
        _split(panels, "row"),
        "Plot!attitude" if plotted else None,
        "RosOut!events" if log is not None else None,
    ]
    right = _split([r for r in rows if r is not None], "column")
    return {
        "configById": config,
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": "3D!uavtool" if right is None else _pair("3D!uavtool", right, "row", 55),
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


def _three_d(topics: set[str], points: list[tuple[float, float, float]]) -> dict[str, Any]:
    shown = [t for t in (SCENE, MODEL, POSE) if t in topics]
    settings: dict[str, Any] = {t: {"visible": True} for t in shown}
    if POSE in settings:
        settings[POSE].update({"type": "arrow", "arrowScale": [2, 0.3, 0.3]})
    centre, radius, span = _bounds(points)
    # The whole path in view: its bounding sphere fills 90 % of the field of view (a panel
    # taller than wide sees less across than up and down).
    distance = max(radius / math.sin(math.radians(_FOVY_DEG / 2)) / 0.9, 20.0)
    grid = 10 * max(2, math.ceil(span / 10))
    return {
        "followTf": "world",
        "followMode": "follow-none",
        "cameraState": {
            "distance": round(distance, 1),
            "perspective": True,
            "phi": 50,
            "thetaOffset": 30,
            "target": [0, 0, 0],
            "targetOffset": [round(c, 1) for c in centre],  # where the 3D panel looks
            "targetOrientation": [0, 0, 0, 1],
            "fovy": _FOVY_DEG,
            "near": 0.5,
            "far": 5000,
        },
        "topics": settings,
        "layers": {
            "grid": {
                "layerId": "foxglove.Grid",
                "instanceId": "grid",
                "label": "Ground (10 m grid)",
                "visible": True,
                "frameLocked": True,
                "size": grid,
                "divisions": grid // 10,
                "lineWidth": 1,
                "color": "#9e9e9e",
                "position": [round(centre[0], 1), round(centre[1], 1), 0],
                "rotation": [0, 0, 0],
                "order": 1,
            }
        },
    }


def _bounds(
    points: list[tuple[float, float, float]],
) -> tuple[tuple[float, ...], float, float]:
    """The centre of ``points``' bounding box, the radius of its sphere and its larger
    horizontal side (around the origin, 50 m, without points)."""
    if not points:
        return (0.0, 0.0, 0.0), 50.0, 100.0
    lo = [min(p[i] for p in points) for i in range(3)]
    hi = [max(p[i] for p in points) for i in range(3)]
    centre = tuple((a + b) / 2 for a, b in zip(lo, hi, strict=True))
    return centre, math.dist(lo, hi) / 2, max(hi[0] - lo[0], hi[1] - lo[1])


def _plot(paths: list[str]) -> dict[str, Any]:
    return {
        "paths": [{"value": p, "enabled": True, "timestampMethod": "receiveTime"} for p in paths],
        "showLegend": True,
        "legendDisplay": "floating",
        "showPlotValuesInLegend": True,
        "showXAxisLabels": True,
        "showYAxisLabels": True,
        "isSynced": True,
        "xAxisVal": "timestamp",
        "sidebarDimension": 240,
    }


def _split(items: list[Any], direction: str) -> Any:
    """A mosaic node that shares its space evenly between ``items`` (None when empty)."""
    if not items:
        return None
    if len(items) == 1:
        return items[0]
    return _pair(items[0], _split(items[1:], direction), direction, 100 / len(items))


def _pair(first: Any, second: Any, direction: str, percent: float) -> dict[str, Any]:
    return {
        "first": first,
        "second": second,
        "direction": direction,
        "splitPercentage": round(percent, 1),
    }
