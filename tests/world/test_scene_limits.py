"""Limits on scene files: hostile files are refused quickly, in little memory, on one line
naming the file and, where known, the line."""

from __future__ import annotations

import json
import math
import time
import tracemalloc
from pathlib import Path
from typing import Any

import pytest

from tests.cli.bad_inputs import BAD_SCENES
from uavtool.world import SceneError, limits, load_scene, scene_from_dict
from uavtool.world.scene import parse_scene


def _building(k: int, x_m: float, *, n: int = 4) -> dict[str, Any]:
    fp = [[x_m, 0.0], [x_m + 4.0, 0.0], [x_m + 4.0, 3.0], [x_m, 3.0]][:n]
    return {"name": f"b{k}", "color": [200, 30, 30], "blocks": [{"footprint": fp, "top_m": 5}]}


def _circle(x_m: float, n: int) -> list[list[float]]:
    turns = [2.0 * math.pi * i / n for i in range(n)]
    return [[x_m + 100.0 * math.cos(t), 100.0 * math.sin(t)] for t in turns]


def _refused(text: str, name: str, match: str) -> str:
    with pytest.raises(SceneError, match=match) as info:
        parse_scene(text, source=name, suffix=Path(name).suffix)
    message = str(info.value)
    assert message.startswith(name) and "\n" not in message
    return message


def test_alias_bomb_is_refused_in_under_a_second_and_100_mb() -> None:
    text = BAD_SCENES["alias-bomb.yaml"]
    assert len(text) < 400  # stands for 9**9 = 387 million strings
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        _refused(text, "bomb.yaml", r"^bomb.yaml:\d+: more than 100000 values with aliases")
    finally:
        elapsed_s = time.perf_counter() - t0
        _, peak_bytes = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    print(f"alias bomb refused in {elapsed_s * 1000:.1f} ms, peak {peak_bytes / 1e6:.2f} MB")
    assert elapsed_s < 1.0
    assert peak_bytes < 100e6


def test_small_aliases_are_still_allowed() -> None:
    text = (
        "target: a\nbuildings:\n"
        "  - {name: a, color: &red [200, 30, 30],\n"
        "     blocks: [{footprint: [[0, 0], [4, 0], [4, 3]], top_m: 5}]}\n"
        "  - {name: b, color: *red, blocks: [{footprint: [[10, 0], [14, 0], [14, 3]], top_m: 3}]}\n"
    )
    assert parse_scene(text, source="s.yaml").buildings[1].color_rgb == (200, 30, 30)


@pytest.mark.parametrize(
    ("name", "match"),
    [
        # libyaml (PyYAML >= 6.0.4) may refuse the nesting first, in its own words
        ("deep.yaml", r"^deep.yaml(:\d+)?: .*nest(ed|ing)"),
        ("deep.json", r"^deep.json: nested deeper than 16 levels"),
        ("deep.toml", r"^deep.toml: nested deeper than 16 levels"),
        (
            "int-400-digits.yaml",
            r"^int-400-digits.yaml:7: buildings\[0\].blocks\[0\].top_m: expected a finite number",
        ),
        ("int-5000-digits.yaml", r"^int-5000-digits.yaml:7: a value longer than 4096 characters"),
        ("int-5000-digits.json", r"^int-5000-digits.json: invalid JSON: a number too long"),
        (
            "hex-4000-digits.yaml",
            r"^hex-4000-digits.yaml:7: buildings\[0\].blocks\[0\].top_m: expected a finite "
            "number, got a number thousands of digits long$",
        ),
        (
            "hex-4000-digits-color.yaml",
            r"^hex-4000-digits-color.yaml:4: buildings\[0\].color: expected \[r, g, b\] with "
            "integers 0-255, got a number thousands of digits long$",
        ),
        (
            "hex-4000-digits-footprint.yaml",
            r"^hex-4000-digits-footprint.yaml:\d+: buildings\[0\].blocks\[0\].footprint\[0\]"
            r"\[0\]: expected a finite number, got a number thousands of digits long$",
        ),
        (
            "hex-4000-digits.toml",
            r"^hex-4000-digits.toml: buildings\[0\].blocks\[0\].top_m: expected a finite "
            "number, got a number thousands of digits long$",
        ),
        (
            "duplicate-key.yaml",
            r"^duplicate-key.yaml:2: duplicate key 'target' \(first on line 1\)",
        ),
        ("duplicate-key.json", r"^duplicate-key.json: duplicate key 'target'"),
        (
            "recursive-alias.yaml",
            r"^recursive-alias.yaml:2: alias \*x is undefined or inside its own anchor",
        ),
        ("bad-date.yaml", r"^bad-date.yaml: invalid YAML value: month must be in 1..12"),
        (
            "far-away.yaml",
            r"^far-away.yaml:6: buildings\[0\].blocks\[0\].footprint\[1\]: "
            "more than 10000 m from home",
        ),
        ("tall.yaml", r"^tall.yaml:7: buildings\[0\].blocks\[0\].top_m: at most 1000 m"),
        ("100k-vertices.json", r"^100k-vertices.json: larger than 256 KiB"),
        ("10k-buildings.json", r"^10k-buildings.json: larger than 256 KiB"),
    ],
)
def test_hostile_files_are_refused_on_one_line(name: str, match: str) -> None:
    t0 = time.perf_counter()
    _refused(BAD_SCENES[name], name, match)
    assert time.perf_counter() - t0 < 2.0


def test_large_scene_data_is_refused_before_any_geometry() -> None:
    many = {"target": "b0", "buildings": [_building(k, 10.0 * k) for k in range(10_000)]}
    t0 = time.perf_counter()
    with pytest.raises(SceneError, match=r"buildings: at most 200 items allowed, got 10000"):
        scene_from_dict(many)
    ring = [[10 * (k % 2), float(k)] for k in range(100_000)]
    spiky = {
        "target": "b0",
        "buildings": [{**_building(0, 0.0), "blocks": [{"footprint": ring, "top_m": 5}]}],
    }
    with pytest.raises(SceneError, match=r"footprint: at most 256 items allowed, got 100000"):
        scene_from_dict(spiky)
    assert time.perf_counter() - t0 < 1.0
    blocks = [
        {"footprint": [[0, 0], [250, 0], [250, 1], [0, 1]], "base_m": k, "top_m": k + 1}
        for k in range(32)
    ]
    wide = {
        "target": "b0",
        "buildings": [{**_building(k, 1000.0 * k), "blocks": blocks} for k in range(1)],
    }
    assert len(scene_from_dict(wide).buildings[0].blocks) == 32
    many_vertices = [
        {**_building(k, 0.0), "blocks": [{"footprint": _circle(300.0 * k, 250), "top_m": 5}]}
        for k in range(17)
    ]
    with pytest.raises(
        SceneError, match=f"more than {limits.MAX_SCENE_VERTICES} footprint vertices"
    ):
        scene_from_dict({"target": "b0", "buildings": many_vertices})


def test_two_hundred_buildings_validate_fast_and_overlaps_are_still_found() -> None:
    data = {
        "target": "b0",
        "buildings": [_building(k, 10.0 * k) for k in range(limits.MAX_BUILDINGS)],
    }
    t0 = time.perf_counter()
    assert len(scene_from_dict(data).buildings) == limits.MAX_BUILDINGS
    assert time.perf_counter() - t0 < 2.0
    data["buildings"][150] = _building(150, 10.0 * 37 + 1.0)  # onto b37
    data["buildings"][190] = _building(190, 10.0 * 12 + 2.0)  # onto b12, reported second
    with pytest.raises(
        SceneError, match=r"buildings\[150\]: building 'b150' overlaps building 'b37'"
    ):
        scene_from_dict(data)


def test_file_size_is_checked_before_reading(tmp_path: Path) -> None:
    path = tmp_path / "big.json"
    path.write_text(json.dumps({"pad": "x" * limits.MAX_FILE_BYTES}))
    with pytest.raises(SceneError, match=r"big.json: larger than 256 KiB, not a scene"):
        load_scene(path)


def test_a_file_that_is_not_a_scene_is_not_echoed_into_the_error(tmp_path: Path) -> None:
    # /etc/shadow read as YAML is a mapping whose keys are its lines, password hashes and all.
    shadow = tmp_path / "shadow"
    shadow.write_text(
        "root:$6$Zx9SALT$SECRETHASHabc:20228:0:99999:7:::\ndaemon:*:20228:0:99999:7:::\n"
    )
    with pytest.raises(SceneError) as info:
        load_scene(shadow)
    message = str(info.value)
    assert "SECRETHASH" not in message and "20228" not in message and "$6$" not in message
    assert message.startswith(f"{shadow}:1: a key that is not a scene key (is this a scene file?)")
