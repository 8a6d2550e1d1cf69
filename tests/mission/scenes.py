"""Scenes made for one branch of the mission, built from ``paper`` as plain data."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from uavtool.mission import MissionParams, Params
from uavtool.runner.fly import FlightSummary, FlyConfig, fly
from uavtool.world import Scene, load_scene, scene_from_dict, scene_to_dict

# Wall colours: hues far from the red target and from each other.
_WALLS = {
    "north": ((40, 90, 220), (-12.0, 8.0, 12.0, 10.0)),
    "south": ((60, 170, 70), (-12.0, -10.0, 12.0, -8.0)),
    "west": ((230, 200, 40), (-13.0, -6.5, -11.0, 6.5)),
    "east": ((140, 70, 190), (11.0, -6.5, 13.0, 6.5)),
}


def on_grey_ground(name: str, target: str, buildings: list[dict[str, Any]]) -> Scene:
    """A scene of ``buildings`` (scene-file dicts) on grey ground, lit as the paper's."""
    return scene_from_dict(
        {
            "version": 1,
            "name": name,
            "origin": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_amsl_m": 400.0, "heading_deg": 0.0},
            "ground": {"color": [128, 128, 128]},
            "sky": {"color": [205, 218, 232]},
            "lighting": {"sun_azimuth_deg": 150.0, "sun_elevation_deg": 60.0, "ambient": 0.55},
            "target": target,
            "buildings": buildings,
        }
    )


DATA = Path(__file__).parent / "data"


def fly_data_scene(name: str) -> tuple[FlightSummary, list[str]]:
    """Fly ``tests/mission/data/<name>.yaml`` without recording: its summary and events."""
    events: list[str] = []
    summary = fly(
        FlyConfig(scene=str(DATA / f"{name}.yaml"), no_record=True),
        progress=lambda e, _t: events.append(e),
    )
    return summary, events


def with_mission(**changes: Any) -> Params:
    """Default parameters with some ``mission.*`` values changed."""
    return Params(mission=dataclasses.replace(MissionParams(), **changes))


def _paper() -> dict[str, Any]:
    return scene_to_dict(load_scene("paper"))


def _red(data: dict[str, Any]) -> dict[str, Any]:
    return next(b for b in data["buildings"] if b["name"] == "red")


def _box(name: str, colour: tuple[int, int, int], box: tuple[float, ...]) -> dict[str, Any]:
    x0, y0, x1, y1 = box
    ring = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    return {"name": name, "color": list(colour), "blocks": [{"footprint": ring, "top_m": 8.0}]}


def walled(sides: tuple[str, ...]) -> Scene:
    """Paper's red building moved to home, with 8 m high walls 4-6 m from it on ``sides``
    (``north``, ``south``, ``west``, ``east``): a wall on both long sides blocks every front
    viewpoint, one on both short sides every right one (obstacles count as infinitely tall)."""
    data = _paper()
    red = _red(data)
    for block in red["blocks"]:
        block["footprint"] = [[x - 10.0, y + 8.0] for x, y in block["footprint"]]
    walls = [_box(side, *_WALLS[side]) for side in sides]
    data.update(name="walled-" + "-".join(sides), buildings=[red, *walls])
    return scene_from_dict(data, source="walled")


def rotated(angle_deg: float, name: str = "paper") -> Scene:
    """A built-in scene with every building turned ``angle_deg`` anticlockwise about home:
    from a vehicle facing north, its photos show what a vehicle facing ``angle_deg`` (east
    of north) would see of the scene as it is. (The overviews face the nearest of north,
    east, south and west, and the looks keep that heading, so turning the vehicle turns
    the photos by multiples of 90° only.)"""
    data = rotate_buildings(scene_to_dict(load_scene(name)), angle_deg)
    data.update(name=f"{name}-rotated-{angle_deg:g}")
    return scene_from_dict(data, source="rotated")


def rotate_buildings(data: dict[str, Any], angle_deg: float) -> dict[str, Any]:
    """Scene ``data`` with every footprint turned ``angle_deg`` anticlockwise about home."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    for building in data["buildings"]:
        for block in building["blocks"]:
            block["footprint"] = [[x * c - y * s, x * s + y * c] for x, y in block["footprint"]]
    return data


def cross_target() -> Scene:
    """Paper with the red building replaced by a red cross: its picture matches nothing."""
    data = _paper()
    cross = [[8, -10], [10, -10], [10, -14], [12, -14], [12, -10], [14, -10], [14, -8]]
    cross += [[12, -8], [12, -4], [10, -4], [10, -8], [8, -8]]
    _red(data)["blocks"] = [{"footprint": cross, "top_m": 6.0}]
    return scene_from_dict(data, source="cross")


def cyan_target() -> Scene:
    """Paper with the red building painted cyan: its picture is the red building's outline
    in a colour no building of paper has."""
    data = _paper()
    _red(data)["color"] = [40, 200, 200]
    return scene_from_dict(data, source="cyan")


def out_of_view() -> Scene:
    """Only the red building, 150 m east: the overview photo from home shows nothing."""
    data = _paper()
    red = _red(data)
    for block in red["blocks"]:
        block["footprint"] = [[x + 150.0, y] for x, y in block["footprint"]]
    data.update(name="out-of-view", buildings=[red])
    return scene_from_dict(data, source="out-of-view")


def turned(heading_deg: float, name: str = "paper") -> Scene:
    """A built-in scene whose vehicle starts facing ``heading_deg`` (the overviews and looks
    face the nearest of north, east, south and west: their photos see the roofs turned by
    that multiple of 90°)."""
    data = scene_to_dict(load_scene(name))
    data["origin"]["heading_deg"] = heading_deg
    data.update(name=f"{name}-heading-{heading_deg:g}")
    return scene_from_dict(data, source="turned")
