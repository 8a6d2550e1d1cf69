"""``uavtool export REC --layout FILE``: a Foxglove / Lichtblick layout that shows the
recording, one vehicle's or a fleet's. (That Lichtblick itself draws every panel of it is
`tests/viewer`'s part.)"""

from __future__ import annotations

import importlib
import json
import math
import re
from pathlib import Path
from typing import Any

from click.testing import CliRunner
from google.protobuf.json_format import MessageToDict  # type: ignore[import-untyped]

from tests.recording.sample import write_sample
from uavtool.cli import cli
from uavtool.recording.foxglove_layout import layout_for
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import EVENTS, FIX, IMAGE, MODEL, POSE, SCENE, TARGET
from uavtool.recording.values import LocationFix, PosesInFrame

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden"
PAPER = GOLDEN / "paper.mcap"
FLEET = GOLDEN / "fleet-search.mcap"
"""Three vehicles' search (``uavtool fly --vehicles 3 --mission fleet-search``)."""


def _placed(node: Any, config: dict[str, Any] | None = None) -> list[str]:
    """The panel ids a mosaic layout tree places (with ``config``, those in its tab panels'
    tabs too)."""
    if isinstance(node, str):
        tabs = (config or {}).get(node, {}).get("tabs", []) if node.startswith("Tab!") else []
        return [node] + [p for tab in tabs for p in _placed(tab["layout"], config)]
    return _placed(node["first"], config) + _placed(node["second"], config)


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


# --- a fleet's recording -------------------------------------------------------------------


ATTITUDE = "/mavlink/in/ATTITUDE"
_STEP = re.compile(r'\.(\w+)|\[(\d+)\]|\{([\w.]+)==(\d+|"[^"]*")\}')


def _paths(config: dict[str, Any]) -> list[str]:
    """The message paths of every Plot and State Transitions panel."""
    return [
        line["value"]
        for panel, settings in config.items()
        if panel.startswith(("Plot!", "StateTransitions!"))
        for line in settings["paths"]
    ]


def _named_topics(config: dict[str, Any]) -> set[str]:
    """Every topic a layout's panels name."""
    named = {t for c in config.values() for t in c.get("topics", {})}
    named |= {c["imageMode"]["imageTopic"] for c in config.values() if "imageMode" in c}
    named |= {c["topicToRender"] for c in config.values() if "topicToRender" in c}
    named |= {t for c in config.values() for t in c.get("topicColors", {})}
    return named | {re.split(r"[.{\[]", p, maxsplit=1)[0] for p in _paths(config)}


def _values(reader: RecordingReader, path: str) -> list[Any]:
    """What message path ``path`` (a topic, then ``.field``, ``[index]`` and
    ``{field.field==value}`` steps) picks out of each of its topic's messages, decoded with
    the field names Foxglove's schemas give them (JSON as written, Protobuf by
    foxglove_schemas_protobuf)."""
    topic = re.split(r"[.{\[]", path, maxsplit=1)[0]
    steps = _STEP.findall(path[len(topic) :])
    assert "".join(m.group(0) for m in _STEP.finditer(path[len(topic) :])) == path[len(topic) :]
    found = []
    for message in reader.messages([topic]):
        assert message.schema is not None
        if message.channel.message_encoding == "json":
            items: list[Any] = [json.loads(message.data)]
        else:
            name = message.schema.name.removeprefix("foxglove.")
            pb = getattr(importlib.import_module(f"foxglove_schemas_protobuf.{name}_pb2"), name)
            decoded = pb.FromString(message.data)
            items = [MessageToDict(decoded, always_print_fields_with_no_presence=True)]
        for field, index, where, value in steps:
            if field:
                items = [i[field] for i in items if field in i]
            elif index:
                items = [i[int(index)] for i in items if len(i) > int(index)]
            else:
                wanted = json.loads(value)
                items = [i for i in items if _walk(i, where.split(".")) == wanted]
        found.extend(items)
    return found


def _walk(item: Any, names: list[str]) -> Any:
    for name in names:
        item = item.get(name) if isinstance(item, dict) else None
    return item


def test_a_fleets_layout_has_a_tab_per_vehicle_and_every_vehicle_together() -> None:
    layout = layout_for(FLEET)
    config = layout["configById"]
    placed = _placed(layout["layout"], config)
    assert sorted(placed) == sorted(config)  # every panel placed, once
    tabs = config["Tab!vehicles"]["tabs"]
    assert [t["title"] for t in tabs] == ["uav1", "uav2", "uav3"]
    with RecordingReader(FLEET) as reader:
        topics = set(reader.topics())
    for k, tab in enumerate(tabs, start=1):
        ns = f"/uav{k}"
        assert sorted(_placed(tab["layout"])) == sorted(
            f"{p}!uav{k}" for p in ("3D", "Image", "RosOut")
        )
        three_d = config[f"3D!uav{k}"]
        shown = {t for t, s in three_d["topics"].items() if s["visible"]}
        assert shown == {ns + t for t in (SCENE, MODEL, POSE) if ns + t in topics}
        assert three_d["transforms"] == {"frame:camera": {"visible": False}}
        assert config[f"Image!uav{k}"]["imageMode"]["imageTopic"] == ns + IMAGE
        assert config[f"RosOut!uav{k}"]["topicToRender"] == ns + EVENTS
    assert any(MODEL in t for c in config.values() for t in c.get("topics", {}))
    assert config["Image!target"]["imageMode"]["imageTopic"] == TARGET
    # Every topic the layout names is in the recording, and the map shows every vehicle's fix.
    assert _named_topics(config) <= topics
    colours = config["map!fleet"]["topicColors"]
    assert sorted(colours) == [f"/uav{k}{FIX}" for k in (1, 2, 3)]
    assert len(set(colours.values())) == 3
    # One series per vehicle in each plot, in the vehicle's colour on the map.
    for panel in ("Plot!height", "Plot!attitude", "StateTransitions!modes"):
        lines = config[panel]["paths"]
        assert [line["color"] for line in lines] == list(colours.values())
        assert [line["label"].split()[0] for line in lines] == ["uav1", "uav2", "uav3"]


def test_every_series_of_a_fleets_layout_plots_its_own_vehicle() -> None:
    config = layout_for(FLEET)["configById"]
    with RecordingReader(FLEET) as reader:
        sysids = [json.loads(m.data)["header"]["sysid"] for m in reader.messages([ATTITUDE])]
        for panel in ("Plot!height", "Plot!attitude", "StateTransitions!modes"):
            for line in config[panel]["paths"]:
                k = int(line["label"].split()[0].removeprefix("uav"))
                values = _values(reader, line["value"])
                if panel == "Plot!height":  # its pose's height, every sample; it flew
                    heights = [
                        p.position_m[2]
                        for e in reader.entries([f"/uav{k}{POSE}"])
                        if isinstance(e.value, PosesInFrame)
                        for p in e.value.poses
                    ]
                    assert values == heights and max(heights) > 5
                elif panel == "Plot!attitude":  # its roll, from its own frames only
                    assert len(values) == sysids.count(k)
                    assert all(isinstance(v, float | int) for v in values)
                else:  # its flight modes, from the take-off to its landing
                    assert {"STABILIZE", "GUIDED"} <= set(values)
                    assert {"LAND", "RTL"} & set(values)


def test_each_vehicles_3d_view_holds_the_path_it_flew() -> None:
    config = layout_for(FLEET)["configById"]
    with RecordingReader(FLEET) as reader:
        for k in (1, 2, 3):
            camera = config[f"3D!uav{k}"]["cameraState"]
            points = [
                p.position_m
                for e in reader.entries([f"/uav{k}{POSE}"])
                if isinstance(e.value, PosesInFrame)
                for p in e.value.poses
            ]
            reach = camera["distance"] * math.sin(math.radians(camera["fovy"] / 2))
            assert max(math.dist(p, camera["targetOffset"]) for p in points) < reach


def test_the_map_opens_on_the_whole_fleet() -> None:
    panel = layout_for(FLEET)["configById"]["map!fleet"]
    zoom, centre = panel["zoomLevel"], panel["center"]

    def pixel(lat: float, lon: float) -> tuple[float, float]:  # Web Mercator, at the zoom
        scale = 256 * 2**zoom
        y = math.log(math.tan(math.radians(lat)) + 1 / math.cos(math.radians(lat)))
        return (lon + 180) / 360 * scale, (1 - y / math.pi) / 2 * scale

    with RecordingReader(FLEET) as reader:
        fixes = [e.value for e in reader.entries([f"/uav{k}{FIX}" for k in (1, 2, 3)])]
    cx, cy = pixel(centre["lat"], centre["lon"])
    xs, ys = zip(
        *(pixel(f.latitude_deg, f.longitude_deg) for f in fixes if isinstance(f, LocationFix)),
        strict=True,
    )
    # All within a map panel 300 px across, and one zoom step closer would not keep them.
    assert all(abs(x - cx) < 150 for x in xs) and all(abs(y - cy) < 150 for y in ys)
    assert max(max(xs) - min(xs), max(ys) - min(ys)) > 300 / 2 / 1.2


def test_export_writes_a_fleets_layout_even_of_a_cut_file(tmp_path: Path) -> None:
    out = tmp_path / "fleet.layout.json"
    result = CliRunner().invoke(cli, ["export", str(FLEET), "--layout", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output == f"wrote a layout of 15 panels to {out}\n"
    assert json.loads(out.read_text()) == layout_for(FLEET)
    # A fleet's file cut mid-flight (no outcomes at its end yet): still its vehicles' layout.
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(FLEET.read_bytes()[: FLEET.stat().st_size // 2])
    result = CliRunner().invoke(cli, ["export", str(cut), "--layout", str(out)])
    assert result.exit_code == 3, result.output
    tabs = json.loads(out.read_text())["configById"]["Tab!vehicles"]["tabs"]
    assert [t["title"] for t in tabs] == ["uav1", "uav2", "uav3"]
