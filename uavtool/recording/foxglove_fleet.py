"""The Foxglove / Lichtblick layout of a fleet's recording (``uavtool fly --vehicles N``).

Every vehicle's pose, route, photos and model are in a frame of its own — ENU metres around its
own home — yet all name it ``world``, and every vehicle's camera pose names its frame
``camera``: one 3D panel would draw the vehicles over each other, their homes' spacing lost,
and the ``camera`` axes of whichever vehicle took the last photo. So each vehicle gets a tab
of its own (a ``Tab`` panel, one tab per vehicle, which also keeps the app's WebGL contexts
few for a fleet of 16): its 3D view framed on its path (the shared ``camera`` axes hidden), its
camera image and its event log. Beside the tabs, what shows the fleet together: a Map of every
vehicle's WGS-84 fix (``/uavK/vehicle/fix``: where they really flew, side by side), the
target picture, each vehicle's height above its home, its roll (``/mavlink/in/ATTITUDE``,
shared, told apart by system id) and its flight mode over time. A vehicle has one colour in
the map, the plots and its pose arrow.
"""

from __future__ import annotations

from typing import Any

from uavtool.recording.fleet import vehicle_prefix
from uavtool.recording.foxglove_panels import (
    Point,
    image,
    log,
    map_panel,
    pair,
    plot,
    series,
    split,
    state_transitions,
    tabs,
    three_d,
)
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import (
    CAMERA_POSE,
    EVENTS,
    FIX,
    IMAGE,
    MODEL,
    OBSERVATIONS,
    POSE,
    SCENE,
    TARGET,
    VEHICLE_EVENTS,
)
from uavtool.recording.values import LocationFix, PosesInFrame

COLOURS = (
    "#4e79a7",
    "#f28e2b",
    "#e15759",
    "#76b7b2",
    "#59a14f",
    "#edc948",
    "#b07aa1",
    "#ff9da7",
    "#9c755f",
    "#bab0ac",
)
"""Each vehicle's colour, by its place in the fleet (Tableau's ten, then again)."""
ATTITUDE = "/mavlink/in/ATTITUDE"


def fleet_layout(reader: RecordingReader, topics: set[str], vehicles: list[int]) -> dict[str, Any]:
    """The layout of the fleet ``vehicles`` (system ids) whose recording ``reader`` reads and
    holds ``topics``."""
    poses = {k: vehicle_prefix(k) + POSE for k in vehicles}
    fixes = {k: vehicle_prefix(k) + FIX for k in vehicles}
    points: dict[str, list[Point]] = {t: [] for t in poses.values()}
    where: dict[str, list[tuple[float, float]]] = {t: [] for t in fixes.values() if t in topics}
    for entry in reader.entries([t for t in (*poses.values(), *where) if t in topics]):
        if isinstance(entry.value, PosesInFrame):
            points[entry.topic].extend(p.position_m for p in entry.value.poses)
        elif isinstance(entry.value, LocationFix):
            where[entry.topic].append((entry.value.latitude_deg, entry.value.longitude_deg))
    colour = {k: COLOURS[i % len(COLOURS)] for i, k in enumerate(vehicles)}
    config: dict[str, Any] = {}
    pages = [
        (f"uav{k}", _vehicle(config, topics, k, points[poses[k]], colour[k])) for k in vehicles
    ]
    config["Tab!vehicles"] = tabs(pages)
    top: list[str] = []
    if where:
        shown = {t: colour[k] for k, t in fixes.items() if t in where}
        config["map!fleet"] = map_panel(where, shown)
        top.append("map!fleet")
    if TARGET in topics:
        config["Image!target"] = image(TARGET)
        top.append("Image!target")
    rows: list[str] = []
    heights = [
        series(f"{poses[k]}.poses[0].position.z", label=f"uav{k} height (m)", colour=colour[k])
        for k in vehicles
        if poses[k] in topics
    ]
    if heights:
        config["Plot!height"] = plot(heights)
        rows.append("Plot!height")
    if ATTITUDE in topics:
        rolls = [
            series(f"{ATTITUDE}{{header.sysid=={k}}}.roll", label=f"uav{k} roll", colour=colour[k])
            for k in vehicles
        ]
        config["Plot!attitude"] = plot(rolls)
        rows.append("Plot!attitude")
    modes = [
        series(
            f'{vehicle_prefix(k)}{OBSERVATIONS}{{type=="Telemetry"}}.mode',
            label=f"uav{k} mode",
            colour=colour[k],
        )
        for k in vehicles
        if vehicle_prefix(k) + OBSERVATIONS in topics
    ]
    if modes:
        config["StateTransitions!modes"] = state_transitions(modes)
        rows.append("StateTransitions!modes")
    right = split(rows, "column")
    if top:  # the map (and the target) over the plots, a little larger than one of them
        above = top[0] if len(top) == 1 else pair(top[0], top[1], "row", 65)
        right = above if right is None else pair(above, right, "column", 40)
    return {
        "configById": config,
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": "Tab!vehicles" if right is None else pair("Tab!vehicles", right, "row", 50),
    }


def _vehicle(
    config: dict[str, Any], topics: set[str], sysid: int, points: list[Point], colour: str
) -> Any:
    """Vehicle ``sysid``'s panels, into ``config``, and the mosaic of its tab: its 3D view
    above its camera image and its event log."""
    prefix, name = vehicle_prefix(sysid), f"uav{sysid}"
    shown = [prefix + t for t in (SCENE, MODEL, POSE) if prefix + t in topics]
    # Every vehicle's camera pose is the frame "camera" in "world": another vehicle's would
    # be drawn in this one's frame.
    hidden = ("camera",) if any(t.endswith(CAMERA_POSE) for t in topics) else ()
    view = three_d(shown, prefix + POSE, points, hidden_frames=hidden)
    if prefix + POSE in view["topics"]:
        view["topics"][prefix + POSE]["gradient"] = [colour, colour]
    config[f"3D!{name}"] = view
    below: list[str] = []
    if prefix + IMAGE in topics:
        config[f"Image!{name}"] = image(prefix + IMAGE)
        below.append(f"Image!{name}")
    events = next((prefix + t for t in (EVENTS, VEHICLE_EVENTS) if prefix + t in topics), None)
    if events is not None:
        config[f"RosOut!{name}"] = log(events)
        below.append(f"RosOut!{name}")
    bottom = split(below, "row")
    return f"3D!{name}" if bottom is None else pair(f"3D!{name}", bottom, "column", 60)
