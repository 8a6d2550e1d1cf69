"""The flight description: what a recording says a flight was, written by fly and read back by
replay, re-fly and view through one decoder — round trip, field by field, so that a new field
cannot be forgotten by either side."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest

from uavtool.flight import DescriptionError, FlightDescription, mission_of
from uavtool.plugins import BUILTIN, MissionRef
from uavtool.recording import RecordingReader
from uavtool.world import load_scene, scene_to_dict

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"

DEFAULT = FlightDescription(
    mission=MissionRef("search", BUILTIN["search"], "0.1.0"),
    params={"mission": {"look_fill": 0.5}},
    scene=scene_to_dict(load_scene("paper")),
    scene_name="paper",
)
OTHER: dict[str, Any] = {
    "mission": MissionRef("orbit", BUILTIN["orbit"], "2.0"),
    "params": {"orbit": {"radius_m": 12.0}, "flight": {"gimbal": False}},
    "scene": scene_to_dict(load_scene("dense")),
    "scene_name": "dense",
    "connect": "tcp:127.0.0.1:5760",
    "camera": "opencv:0",
    "clock": "wall",
    "scene_origin": "vehicle-home",
    "seed": 7,
    "noise": True,
    "wind": (3.5, 270.0),
    "link_outages_s": ((60.0, 10.0), (90.5, 2.0)),
    "vehicle_params": (("WPNAV_SPEED", 800.0), ("MNT1_TYPE", 0.0)),
    "hfov_deg": 75.0,
    "size_px": (800, 600),
    "target": "file",
    "no_gimbal": True,
    "vehicles": 3,
    "offset_line": (45.0, 12.5),
    "homes_m": ((0.0, 0.0), (25.5, -12.0), (-40.0, 30.25)),
    "tool_version": "9.9.9",
}
"""A value other than the default for every field."""


def _round_trip(d: FlightDescription) -> FlightDescription:
    return FlightDescription.from_metadata(d.to_metadata(), source="test")


def test_every_field_has_a_test_value() -> None:
    assert set(OTHER) == {f.name for f in dataclasses.fields(FlightDescription)}


@pytest.mark.parametrize("name", sorted(OTHER))
def test_each_field_survives_the_recording(name: str) -> None:
    changed = dataclasses.replace(DEFAULT, **{name: OTHER[name]})
    back = _round_trip(changed)
    assert getattr(back, name) == OTHER[name]
    assert back == changed


def test_all_fields_at_once() -> None:
    changed = dataclasses.replace(DEFAULT, **OTHER)
    assert _round_trip(changed) == changed


def test_a_recording_from_before_plugins_flew_the_search() -> None:
    """Recordings from before missions were plug-ins name no mission: they were flown by the
    built-in search."""
    with RecordingReader(GOLDEN) as reader:
        meta = {name: dict(record) for name, record in reader.metadata}
    assert meta["mission"]["name"] == "search"
    for key in ("name", "class", "version"):
        del meta["mission"][key]
    d = FlightDescription.from_metadata(meta, source=str(GOLDEN))
    assert (d.mission.name, d.mission.target) == ("search", BUILTIN["search"])
    assert d.scene_name == "paper" and d.clock == "lockstep" and d.target == "scene"


@pytest.mark.parametrize(
    ("record", "key", "value", "words"),
    [
        ("flight", "seed", "abc", "flight.seed is malformed: 'abc' is not an integer"),
        ("flight", "hfov_deg", "1e400", "flight.hfov_deg is malformed: inf is not finite"),
        ("flight", "link_outages_s", "[[0, 1e308]]", "outside 0..1e6 s"),
        ("flight", "size_px", "[100000, 100000]", "100000x100000 is outside 16..8192"),
        ("flight", "noise", "1", "flight.noise is malformed: '1' is not true or false"),
        ("vehicle", "clock", "sundial", "vehicle.clock='sundial': expected one of lockstep, wall"),
        ("mission", "params", "[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ("mission", "params", "[1, 2]", "mission.params is malformed: expected a JSON object"),
        ("scene", "json", '{"a": ' * 50_000 + "1" + "}" * 50_000, "nested too deeply"),
    ],
)
def test_a_crafted_description_is_one_line(record: str, key: str, value: str, words: str) -> None:
    meta = DEFAULT.to_metadata()
    meta[record][key] = value
    with pytest.raises(DescriptionError) as exc:
        FlightDescription.from_metadata(meta, source="crafted.mcap")
    assert words in str(exc.value)
    assert str(exc.value).startswith("crafted.mcap: metadata ")
    assert len(str(exc.value)) < 300


def test_a_recording_names_its_mission_and_its_parameters() -> None:
    ref, params = mission_of(dataclasses.replace(DEFAULT, **OTHER).to_metadata(), source="x")
    assert ref == OTHER["mission"] and params == OTHER["params"]
