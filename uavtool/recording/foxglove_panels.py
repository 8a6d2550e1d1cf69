"""The panels of a Foxglove / Lichtblick layout and the mosaic that places them.

A layout is ``configById`` (each panel's settings, by an id ``Type!name`` whose type the apps
know: ``3D``, ``Image``, ``Plot``, ``RosOut``, ``map``, ``StateTransitions``, ``Tab``) and
``layout``, a tree of splits (react-mosaic's) whose leaves are those ids; a ``Tab`` panel holds
a tree of its own for each tab. `uavtool.recording.foxglove_layout` builds one vehicle's layout
from these, and `uavtool.recording.foxglove_fleet` a fleet's.
"""

from __future__ import annotations

import math
from typing import Any

Point = tuple[float, float, float]

FOVY_DEG = 45.0  # the 3D panel's default vertical field of view
_MAP_PX = 300  # the least side a Map panel of the fleet's layout gets on a laptop's screen
_EARTH_M_PER_PX = 156_543.03392  # one Web Mercator tile pixel at the equator, zoom 0


def three_d(
    shown: list[str], pose: str | None, points: list[Point], *, hidden_frames: tuple[str, ...] = ()
) -> dict[str, Any]:
    """A 3D panel that draws the ``shown`` topics (``pose``, one of them, as an arrow) and
    looks at ``points`` from a distance that fits them all in view; the transforms'
    ``hidden_frames`` are not drawn."""
    settings: dict[str, Any] = {t: {"visible": True} for t in shown}
    if pose in settings:
        settings[pose].update({"type": "arrow", "arrowScale": [2, 0.3, 0.3]})
    centre, radius, span = _bounds(points)
    # The whole path in view: its bounding sphere fills 90 % of the field of view (a panel
    # taller than wide sees less across than up and down).
    distance = max(radius / math.sin(math.radians(FOVY_DEG / 2)) / 0.9, 20.0)
    grid = 10 * max(2, math.ceil(span / 10))
    panel: dict[str, Any] = {
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
            "fovy": FOVY_DEG,
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
    if hidden_frames:
        panel["transforms"] = {f"frame:{f}": {"visible": False} for f in hidden_frames}
    return panel


def _bounds(points: list[Point]) -> tuple[tuple[float, ...], float, float]:
    """The centre of ``points``' bounding box, the radius of its sphere and its larger
    horizontal side (around the origin, 50 m, without points)."""
    if not points:
        return (0.0, 0.0, 0.0), 50.0, 100.0
    lo = [min(p[i] for p in points) for i in range(3)]
    hi = [max(p[i] for p in points) for i in range(3)]
    centre = tuple((a + b) / 2 for a, b in zip(lo, hi, strict=True))
    return centre, math.dist(lo, hi) / 2, max(hi[0] - lo[0], hi[1] - lo[1])


def image(topic: str) -> dict[str, Any]:
    """An Image panel showing ``topic``."""
    return {"imageMode": {"imageTopic": topic}}


def log(topic: str) -> dict[str, Any]:
    """A Log panel (``RosOut``) listing ``topic``'s entries, every level."""
    return {"topicToRender": topic, "searchTerms": [], "minLogLevel": 1}


def series(path: str, *, label: str | None = None, colour: str | None = None) -> dict[str, Any]:
    """One line of a Plot panel: the message path ``path``, on the time it was received."""
    line: dict[str, Any] = {"value": path, "enabled": True, "timestampMethod": "receiveTime"}
    if label is not None:
        line["label"] = label
    if colour is not None:
        line["color"] = colour
    return line


def plot(lines: list[dict[str, Any]]) -> dict[str, Any]:
    """A Plot panel of ``lines`` (`series`) against time, values in its legend."""
    return {
        "paths": lines,
        "showLegend": True,
        "legendDisplay": "floating",
        "showPlotValuesInLegend": True,
        "showXAxisLabels": True,
        "showYAxisLabels": True,
        "isSynced": True,
        "xAxisVal": "timestamp",
        "sidebarDimension": 240,
    }


def state_transitions(lines: list[dict[str, Any]]) -> dict[str, Any]:
    """A State Transitions panel: each of ``lines`` (`series`) a row of its values over time."""
    return {"paths": lines, "isSynced": True, "showPoints": False}


def map_panel(
    fixes: dict[str, list[tuple[float, float]]], colours: dict[str, str]
) -> dict[str, Any]:
    """A Map panel of every WGS-84 fix topic (OpenStreetMap's tiles), each topic its colour
    of ``colours``, centred on all of ``fixes`` ((latitude, longitude) per topic) and zoomed
    in as far as keeps them in view."""
    panel: dict[str, Any] = {
        "layer": "map",
        "customTileUrl": "",
        "disabledTopics": [],
        "followTopic": "",
        "topicColors": colours,
    }
    every = [p for points in fixes.values() for p in points]
    if not every:
        return panel  # the app centres on the first fix it reads
    south, north = min(p[0] for p in every), max(p[0] for p in every)
    west, east = min(p[1] for p in every), max(p[1] for p in every)
    lat = (south + north) / 2
    metres_per_deg = 111_320.0
    span_m = max(
        (north - south) * metres_per_deg,
        (east - west) * metres_per_deg * math.cos(math.radians(lat)),
        20.0,
    )
    # Web Mercator: a pixel at zoom z spans 156543 m · cos(latitude) / 2^z; a margin of 20 %.
    per_px = _EARTH_M_PER_PX * math.cos(math.radians(lat))
    zoom = math.floor(math.log2(per_px * _MAP_PX / (span_m * 1.2)))
    panel["center"] = {"lat": round(lat, 7), "lon": round((west + east) / 2, 7)}
    panel["zoomLevel"] = min(max(zoom, 1), 20)
    return panel


def tabs(pages: list[tuple[str, Any]]) -> dict[str, Any]:
    """A Tab panel: one tab per (title, mosaic tree) of ``pages``, the first one open."""
    return {"activeTabIdx": 0, "tabs": [{"title": t, "layout": tree} for t, tree in pages]}


def split(items: list[Any], direction: str) -> Any:
    """A mosaic node that shares its space evenly between ``items`` (None when empty)."""
    if not items:
        return None
    if len(items) == 1:
        return items[0]
    return pair(items[0], split(items[1:], direction), direction, 100 / len(items))


def pair(first: Any, second: Any, direction: str, percent: float) -> dict[str, Any]:
    """A mosaic node: ``first`` takes ``percent`` of the space (``row``: left of ``second``,
    ``column``: above it)."""
    return {
        "first": first,
        "second": second,
        "direction": direction,
        "splitPercentage": round(percent, 1),
    }
