"""Scene loading, the round trip through plain data, and every validation error."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from uavtool.errors import InputError
from uavtool.world import (
    SceneError,
    builtin_scene_names,
    load_scene,
    scene_from_dict,
    scene_to_dict,
)
from uavtool.world.polygon import signed_area
from uavtool.world.scene import dump_scene, parse_scene

GOOD = """\
name: tiny
target: a
buildings:
  - name: a
    color: [200, 30, 30]
    blocks:
      - footprint: [[0, 0], [4, 0], [4, 3], [0, 3]]
        top_m: 5
  - name: b
    color: [30, 30, 200]
    blocks:
      - footprint: [[10, 0], [14, 0], [14, 3]]
        top_m: 3
"""


def test_builtin_scenes_load_and_round_trip() -> None:
    assert {"paper", "dense", "blocked-front"} <= set(builtin_scene_names())
    for name in builtin_scene_names():
        scene = load_scene(name)
        assert scene.target_building.name == scene.target
        assert scene_from_dict(scene_to_dict(scene), source="x") == scene
        assert parse_scene(dump_scene(scene), source="x.yaml") == scene
        # JSON-serialisable, as the recording embeds it
        assert scene_from_dict(json.loads(json.dumps(scene_to_dict(scene)))) == scene


def test_paper_scene_matches_the_paper() -> None:
    scene = load_scene("paper")
    assert [b.name for b in scene.buildings] == ["yellow", "purple", "blue", "red"]
    assert scene.target == "red"
    assert len(scene.target_building.blocks) > 1  # stacked blocks make the through-holes


def test_clockwise_footprint_is_stored_counter_clockwise() -> None:
    scene = parse_scene(
        GOOD.replace("[[10, 0], [14, 0], [14, 3]]", "[[10, 0], [14, 3], [14, 0]]"), source="s.yaml"
    )
    fp = scene.building("b").blocks[0].footprint_enu_m
    assert set(fp) == {(10.0, 0.0), (14.0, 0.0), (14.0, 3.0)}
    assert signed_area(fp) > 0.0


def test_toml_and_json_files(tmp_path: Path) -> None:
    toml = tmp_path / "s.toml"
    toml.write_text(
        'target = "a"\n[[buildings]]\nname = "a"\ncolor = [1, 2, 3]\n'
        "[[buildings.blocks]]\nfootprint = [[0, 0], [1, 0], [0, 1]]\ntop_m = 2\n"
    )
    assert load_scene(toml).target == "a"
    js = tmp_path / "s.json"
    js.write_text(json.dumps(scene_to_dict(load_scene("paper"))))
    assert load_scene(js) == load_scene("paper")


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [14, 3], [14, 0], [10, 4]]",
            "s.yaml:12: buildings[1].blocks[0].footprint: self-intersecting polygon",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [14, 0]]",
            "buildings[1].blocks[0].footprint: a footprint needs at least 3 vertices, got 2",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [12, 0], [14, 0]]",
            "buildings[1].blocks[0].footprint: polygon has zero area",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [10, 0], [14, 3]]",
            "buildings[1].blocks[0].footprint[1]: repeated vertex",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [14, x], [14, 3]]",
            "buildings[1].blocks[0].footprint[1][1]: expected a number, got str",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[10, 0], [14, 0, 1], [14, 3]]",
            "buildings[1].blocks[0].footprint[1]: expected [east_m, north_m]",
        ),
        (
            "[[10, 0], [14, 0], [14, 3]]",
            "[[1, 1], [5, 1], [5, 4]]",
            "buildings[1]: building 'b' overlaps building 'a'",
        ),
        (
            "top_m: 3",
            "top_m: 0",
            "buildings[1].blocks[0].top_m: top (0.0) must be above base (0.0)",
        ),
        (
            "top_m: 3",
            "top_m: 3\n        base_m: -1",
            "buildings[1].blocks[0].base_m: base must be >= 0",
        ),
        ("top_m: 3", "top_m: .nan", "buildings[1].blocks[0].top_m: expected a finite number"),
        (
            "top_m: 3",
            "top_m: 3\n        height: 3",
            "s.yaml:14: buildings[1].blocks[0].height: unknown key",
        ),
        (
            "color: [30, 30, 200]",
            "color: [30, 30, 256]",
            "s.yaml:10: buildings[1].color: expected [r, g, b] with integers 0-255",
        ),
        ("color: [30, 30, 200]", "color: [30, 30]", "buildings[1].color: expected [r, g, b]"),
        (
            "color: [30, 30, 200]",
            "colour: [30, 30, 200]",
            "buildings[1].colour: unknown key (did you mean 'color'?)",
        ),
        ("name: b", "name: a", "buildings[1].name: duplicate building name 'a'"),
        ("target: a", "target: zz", "s.yaml:2: target: no building named 'zz'; buildings: a, b"),
        ("target: a\n", "", "s.yaml:1: missing key 'target'"),
        ("name: tiny", "name: tiny\nversion: 2", "version: unsupported scene format version 2"),
        (
            "name: tiny",
            "name: tiny\nlighting: {sun_elevation_deg: 0}",
            "lighting.sun_elevation_deg: sun elevation must be in (0, 90]",
        ),
        (
            "name: tiny",
            "name: tiny\nlighting: {ambient: 2}",
            "lighting.ambient: ambient must be in [0, 1]",
        ),
        (
            "name: tiny",
            "name: tiny\norigin: {lat_deg: 91}",
            "origin.lat_deg: latitude must be in [-90, 90]",
        ),
        (
            "name: tiny",
            "name: tiny\nground: [1, 2, 3]",
            "s.yaml:2: ground: expected a mapping, got list",
        ),
        (
            "name: tiny",
            "name: tiny\nbuildings2: []",
            "buildings2: unknown key (did you mean 'buildings'?)",
        ),
        (
            "    blocks:\n      - footprint: [[10",
            "    blocks: []\n    x:\n      - footprint: [[10",
            "buildings[1].x: unknown key",
        ),
        ("name: b", "name: ''", "buildings[1].name: building name must be a non-empty single line"),
    ],
)
def test_validation_errors_name_file_line_and_key(old: str, new: str, message: str) -> None:
    assert old in GOOD
    with pytest.raises(SceneError) as info:
        parse_scene(GOOD.replace(old, new, 1), source="s.yaml")
    assert message in str(info.value)
    assert str(info.value).startswith("s.yaml")
    assert "\n" not in str(info.value)
    assert isinstance(info.value, InputError)  # the CLI exits 2


def test_blocks_of_one_building_must_not_overlap_in_3d() -> None:
    stacked = GOOD.replace(
        "        top_m: 5\n",
        "        top_m: 5\n      - footprint: [[1, 1], [3, 1], [3, 2]]\n"
        "        base_m: 4\n        top_m: 8\n",
    )
    with pytest.raises(SceneError, match=r"buildings\[0\].blocks\[1\]: overlaps blocks\[0\]"):
        parse_scene(stacked, source="s.yaml")
    # the same footprint resting on top is fine (a stepped tower)
    parse_scene(stacked.replace("base_m: 4", "base_m: 5"), source="s.yaml")


def test_syntax_errors_and_missing_files(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match=r"^s.yaml:4: invalid YAML"):
        parse_scene("target: a\nbuildings:\n  - [\n", source="s.yaml")
    with pytest.raises(SceneError, match="empty scene file"):
        parse_scene("", source="s.yaml")
    with pytest.raises(SceneError, match=r"^s.json:1: invalid JSON"):
        parse_scene("{", source="s.json", suffix=".json")
    with pytest.raises(SceneError, match="invalid TOML"):
        parse_scene("a = ", source="s.toml", suffix=".toml")
    with pytest.raises(SceneError, match=r"no such scene file .*built-in scenes: .*paper"):
        load_scene(tmp_path / "missing.yaml")
    with pytest.raises(SceneError, match="expected a mapping, got list"):
        scene_from_dict([1, 2])


def test_unknown_building_lookup() -> None:
    with pytest.raises(SceneError, match="no building 'nope'"):
        load_scene("paper").building("nope")
