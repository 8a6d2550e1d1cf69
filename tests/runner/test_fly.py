"""uavtool fly end to end against the built-in SITL, and its errors."""

from __future__ import annotations

import json
import re
import socket
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.mission import Params, Status
from uavtool.mission.observations import Photo
from uavtool.mission.params import with_overrides
from uavtool.recording import RecordingReader, summarize
from uavtool.replay import load_flight, replay
from uavtool.runner.fly import FlyConfig, fly
from uavtool.world import load_scene, scene_to_dict


@pytest.fixture(scope="module")
def paper_flight(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, Path]:
    path = tmp_path_factory.mktemp("fly") / "paper.mcap"
    summary = fly(FlyConfig(record=path))
    return summary, path


def test_paper_mission_finds_the_red_building_and_builds_its_model(
    paper_flight: tuple[object, Path],
) -> None:
    summary, _path = paper_flight
    o = summary.outcome  # type: ignore[attr-defined]
    e = summary.evaluation  # type: ignore[attr-defined]
    assert o.status is Status.COMPLETED, o.reason
    assert e.matched_building == "red" == e.target_building
    # Red alone is of the target's hue: it is visited first, and matches; no other is.
    assert e.visited == ("red",)
    assert o.model_built
    assert e.model_iou is not None and e.model_iou > 0.85
    # 2 overviews, 1 look, top, front, right and a diagonal (red has two tunnels)
    assert summary.frames == 7  # type: ignore[attr-defined]


def test_recording_is_whole_and_replays_identically(paper_flight: tuple[object, Path]) -> None:
    _, path = paper_flight
    info = summarize(path)
    assert info.whole
    assert info.outcome is not None and info.outcome["status"] == "completed"
    assert replay(load_flight(path)).identical


def test_fly_cli_prints_progress_and_summary(tmp_path: Path) -> None:
    rec = tmp_path / "r.mcap"
    result = CliRunner().invoke(cli, ["fly", "--scene", "blocked-front", "--output", str(rec)])
    assert result.exit_code == 0, result.output
    out = result.output
    assert "points of interest; visiting order" in out
    assert "viewpoint: opposite side" in out  # the front view must fall back
    assert "matched        poi" in out and "(correct: the target is 'red')" in out
    assert "IoU vs ground truth" in out
    assert str(rec) in out
    assert CliRunner().invoke(cli, ["info", str(rec)]).exit_code == 0


def test_link_lost_for_good_ends_the_mission(tmp_path: Path) -> None:
    params = with_overrides(Params(), {"mission.link_lost_abort_s": "8"})
    summary = fly(
        FlyConfig(
            record=tmp_path / "lost.mcap",
            params=params,
            link_outages_s=((40.0, 1000.0),),
        )
    )
    assert summary.outcome.status is Status.LINK_LOST
    assert "no link for" in summary.outcome.reason
    assert summarize(tmp_path / "lost.mcap").whole


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scene", "nowhere"], "nowhere"),
        (["--target", "/nonexistent/target.png"], "--target /nonexistent/target.png"),
        (["--connect", "bogus:1:2"], "connection 'bogus:1:2'"),
        (["--connect", "tcp:127.0.0.1:1", "--timeout", "0.5"], "cannot connect"),
        (["--set", "mission.nope=1"], "unknown parameter 'mission.nope'"),
        (["--set", "mission.look_fill=abc"], "look_fill=abc: expected a finite number in (0, 1]"),
        (["--camera", "webcam"], "--camera 'webcam'"),
        (["--param", "WPNAV_SPEED"], "expected NAME=VALUE"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path: Path, args: list[str], message: str) -> None:
    result = CliRunner().invoke(cli, ["fly", "--output", str(tmp_path / "x.mcap"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output


def test_garbage_instead_of_a_vehicle(tmp_path: Path) -> None:
    """A TCP peer that only sends noise: no heartbeat, a clear error, exit 2."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    port = server.getsockname()[1]

    def noise() -> None:
        conn, _ = server.accept()
        with conn:
            for i in range(1000):  # until the client gives up and hangs up
                try:
                    conn.sendall(bytes((i * 7 + k) % 256 for k in range(512)))
                except OSError:
                    return
                time.sleep(0.005)

    threading.Thread(target=noise, daemon=True).start()
    result = CliRunner().invoke(
        cli,
        ["fly", "--connect", f"tcp:127.0.0.1:{port}", "--timeout", "1", "--no-record"],
    )
    server.close()
    assert result.exit_code == 2, result.output
    assert f"tcp:127.0.0.1:{port}: no heartbeat from a vehicle in 1 s" in result.output


@pytest.mark.parametrize(
    ("args", "status", "code"),
    [
        (["--set", "viewpoints.max_distance_m=5"], "partial: target found; model not built", 3),
        (["--set", "recognize.threshold=0.999"], "no-match", 4),
        (["--link-outage", "15:1e6", "--set", "mission.link_lost_abort_s=5"], "link-lost", 1),
    ],
)
def test_each_outcome_has_its_exit_code(args: list[str], status: str, code: int) -> None:
    result = CliRunner().invoke(cli, ["fly", "-q", "--no-record", *args])
    assert result.exit_code == code, result.output
    assert f"outcome        {status}" in result.output


def test_a_collision_crashes_the_vehicle_and_ends_the_mission(tmp_path: Path) -> None:
    """A mast the colour of the ground (the mission cannot see it) stands where the front
    photo is taken: the vehicle's body touches it on the way down, the vehicle crashes, the
    mission ends 'crashed' with exit code 5, and the recording has the vehicle's word."""
    data = scene_to_dict(load_scene("paper"))
    x, y, r = 10.18, -29.21, 0.4  # paper's front viewpoint
    ring = [[x - r, y - r], [x + r, y - r], [x + r, y + r], [x - r, y + r]]
    grey = list(data["ground"]["color"])
    data["buildings"].append(
        {"name": "mast", "color": grey, "blocks": [{"footprint": ring, "top_m": 5.9}]}
    )
    scene = tmp_path / "mast.json"
    scene.write_text(json.dumps(data))
    rec = tmp_path / "crash.mcap"
    result = CliRunner().invoke(cli, ["fly", "-q", "--scene", str(scene), "--output", str(rec)])
    assert result.exit_code == 5, result.output
    assert "outcome        crashed: the vehicle disarmed in the air" in result.output
    assert "from building 'mast'" in result.output
    info = summarize(rec)
    assert info.outcome is not None and info.outcome["status"] == "crashed"
    assert float(info.outcome["closest_clearance_m"]) <= 0.0
    with RecordingReader(rec) as reader:
        texts = [str(e.value.payload["text"]) for e in reader.entries(["/mavlink/in/STATUSTEXT"])]  # type: ignore[union-attr]
    assert "Crash: collision with building 'mast'" in texts


def _paper_with(tmp_path: Path, name: str, blocks: list[dict[str, object]], grey: bool) -> Path:
    data = scene_to_dict(load_scene("paper"))
    colour = list(data["ground"]["color"]) if grey else [60, 160, 60]
    data["buildings"].append({"name": name, "color": colour, "blocks": blocks})
    scene = tmp_path / f"{name}.json"
    scene.write_text(json.dumps(data))
    return scene


def _square(x: float, y: float, r: float) -> list[list[float]]:
    return [[x - r, y - r], [x + r, y - r], [x + r, y + r], [x - r, y + r]]


def test_a_crash_on_the_way_home_is_a_crash_whatever_came_before(tmp_path: Path) -> None:
    """The search and the model done, a pole the mission cannot see (ground-coloured and
    0.5 m thick: under three pixels of the 117 m overview) stands on the way home:
    the flight is 'crashed' (exit 5) in the summary and the recording's outcome, the mission
    sends nothing into the wreck afterwards, and the model built before is still counted."""
    scene = _paper_with(
        tmp_path, "mast", [{"footprint": _square(20, -18.3, 0.25), "top_m": 14}], True
    )
    rec = tmp_path / "home-crash.mcap"
    result = CliRunner().invoke(cli, ["fly", "-q", "--scene", str(scene), "--output", str(rec)])
    assert result.exit_code == 5, result.output
    assert "outcome        crashed: the vehicle disarmed in the air" in result.output
    assert "after 'completed: model built'" in result.output
    info = summarize(rec)
    assert info.outcome is not None and info.outcome["status"] == "crashed"
    with RecordingReader(rec) as reader:
        outputs = [e.value.payload for e in reader.entries(["/mission/outputs"])]  # type: ignore[union-attr]
    last = outputs[-1]
    assert last["type"] == "Outcome" and last["status"] == "crashed" and last["model_built"]
    crash = next(i for i, o in enumerate(outputs) if "disarmed in the air" in str(o.get("text")))
    assert not [o for o in outputs[crash:] if o["type"] in ("GoTo", "SetMode", "Takeoff")]


def test_a_refused_take_off_ends_disarmed_on_the_ground(tmp_path: Path) -> None:
    """Home under a deck: the vehicle refuses the take-off (MAV_RESULT_DENIED, a final
    answer): the mission ends at once with the vehicle's reason, does not send RTL (its
    climb would hit the deck) but LAND, which disarms the vehicle where it stands."""
    deck = [
        {"footprint": _square(-2.5, -2.5, 0.5), "top_m": 7},
        {"footprint": _square(0, 0, 3), "base_m": 7, "top_m": 8},
    ]
    scene = _paper_with(tmp_path, "deck", deck, False)
    result = CliRunner().invoke(cli, ["fly", "--scene", str(scene), "--no-record"])
    assert result.exit_code == 1, result.output
    assert (
        "outcome        aborted: take-off to 45 m: refused (MAV_RESULT_DENIED): "
        "Takeoff: obstacle above at 7.0 m\n" in result.output
    )
    assert "(attempt " not in result.output
    assert "still on the ground: LAND to disarm" in result.output
    assert "returning home (RTL)" not in result.output
    assert "landed and disarmed" in result.output


@pytest.mark.parametrize(
    ("name", "colour"),
    [("concrete", [165, 165, 170]), ("dark red", [120, 25, 25]), ("black", [30, 30, 30])],
)
def test_a_building_of_no_building_colour_is_an_obstacle(
    tmp_path: Path, name: str, colour: list[int]
) -> None:
    """A 14 m block on the way home that the vectorizer leaves out (grey; a darker shade of
    the target's red; black): the flight used to cross it at 11.6 m and crash. Everything
    that is not ground is an obstacle: its roof is measured and the way home crosses over it
    by the safety margin. The one of the target's hue is a point of interest as well (it
    might be the target), measured like the survey's buildings, and looked at."""
    data = scene_to_dict(load_scene("paper"))
    block = {"footprint": _square(20, -18.3, 1.5), "top_m": 14}
    data["buildings"].append({"name": "block", "color": colour, "blocks": [block]})
    scene = tmp_path / "block.json"
    scene.write_text(json.dumps(data))
    result = CliRunner().invoke(cli, ["fly", "--scene", str(scene), "--no-record"])
    assert result.exit_code == 0, result.output
    if name == "dark red":
        # its own roof, told by geometry, not the brightest shade of the hue: a building
        # of the target's hue, measured and looked at, and not the target
        assert "roofs measured from above: 1 more, 5 of 5" in result.output
        assert "point of interest 4: no match" in result.output
    else:
        found = re.search(
            r"1 obstacles no roof of a building colour explains .*: roofs ([\d.]+) m",
            result.output,
        )
        assert found is not None and float(found.group(1)) == pytest.approx(14.0, abs=0.5), name
    # the safety margin is 4 m; the roof measured up to half a metre low may take from it
    clearance = re.search(r"clearance +(-?[\d.]+) m from building", result.output)
    assert clearance is not None and float(clearance.group(1)) >= 3.5


def test_a_tower_taller_than_expected_is_measured_before_it_is_flown_near(tmp_path: Path) -> None:
    """A 45 m tower (taller than mission.assumed_roof_m, 25 m) out of the lower overview's
    view: the mission measures it from above before descending anywhere, crosses over it
    with the safety margin (4 m) and never comes closer (it passed within 0.42 m before)."""
    data = {
        "version": 1,
        "name": "tower",
        "target": "red",
        "buildings": [
            {"name": "tower", "color": [40, 90, 220],
             "blocks": [{"footprint": _square(14, 12, 4), "top_m": 45}]},
            {"name": "red", "color": [210, 40, 40],
             "blocks": [{"footprint": [[24, 24], [34, 24], [34, 28], [28, 28], [28, 34],
                                       [24, 34]], "top_m": 6}]},
        ],
    }  # fmt: skip
    scene = tmp_path / "tower.json"
    scene.write_text(json.dumps(data))
    result = CliRunner().invoke(cli, ["fly", "--scene", str(scene), "--no-record"])
    assert result.exit_code == 0, result.output
    assert "taller than expected: 0 (45.0 m)" in result.output
    clearance = re.search(r"clearance +(-?[\d.]+) m from building", result.output)
    assert clearance is not None and float(clearance.group(1)) >= 4.0


def test_an_arch_gets_a_diagonal_photo_and_its_model_keeps_the_tunnels(tmp_path: Path) -> None:
    """Red in the `arch` scene is an L-shaped deck on two pillars: the front and right photos
    see through under its legs but not under its corner (a pillar stands behind it from both
    sides). The model from them is open underneath, so the mission takes a diagonal photo,
    and the model built with it is open all the way through."""
    rec = tmp_path / "arch.mcap"
    summary = fly(FlyConfig(scene="arch", record=rec))
    o, e = summary.outcome, summary.evaluation
    assert o.status is Status.COMPLETED, o.reason
    assert e.matched_building == "red"
    tags = [obs.tag for obs in load_flight(rec).observations if isinstance(obs, Photo)]
    assert tags[-3:] == ["front", "right", "diagonal"], tags
    assert e.tunnel_kept is True
    assert e.model_iou is not None and e.model_iou > 0.85
