"""``uavtool fly --vehicles N``: a fleet mission on built-in vehicles in one lockstep world,
recorded in one file, replayed and re-flown byte for byte; and its errors."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.errors import InputError
from uavtool.examples.fleet_survey import FleetSurveyMission, FleetSurveyParams
from uavtool.flight import FlightDescription
from uavtool.mission import Level, Status
from uavtool.mission.fleet import FleetParams
from uavtool.mission.fleet_search import FleetSearchParams
from uavtool.mission.params import with_overrides
from uavtool.recording import RecordingReader, summarize
from uavtool.replay import load_flight
from uavtool.replay.fleet import replay_fleet
from uavtool.replay.load import is_fleet, load_fleet
from uavtool.replay.refly import refly
from uavtool.runner.fleet import FleetSummary, fly_fleet
from uavtool.runner.fly import FlyConfig, fly
from uavtool.testing import assert_reflies_identically, assert_replays_identically
from uavtool.world.hard import HardOptions, generate_hard_scene


def _config(path: Path | None, **kw: object) -> FlyConfig:
    config = FlyConfig(mission="fleet-survey", vehicles=3, record=path, no_record=path is None)
    return dataclasses.replace(config, **kw)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def survey(tmp_path_factory: pytest.TempPathFactory) -> tuple[FleetSummary, Path]:
    path = tmp_path_factory.mktemp("fleet") / "fleet.mcap"
    return fly_fleet(_config(path)), path


def test_three_vehicles_survey_their_strips_apart(survey: tuple[FleetSummary, Path]) -> None:
    s, _ = survey
    assert s.status is Status.COMPLETED, s.reason
    assert [v.sysid for v in s.vehicles] == [1, 2, 3]
    assert all(v.outcome.status is Status.COMPLETED for v in s.vehicles)
    # Each photographed its own strip, and the last to finish stitched the map of them all.
    strips = [next(r.values for r in v.results if r.tag == "strip") for v in s.vehicles]
    assert [x["vehicle"] for x in strips] == [1, 2, 3] and all(x["photos"] > 0 for x in strips)
    mosaic = [r.values for v in s.vehicles for r in v.results if r.tag == "mosaic"]
    assert len(mosaic) == 1 and mosaic[0]["covered"] == 1.0
    assert mosaic[0]["photos"] == sum(x["photos"] for x in strips)
    # The vehicles never came closer than the separation (the simulator's own measure).
    assert s.closest_approach_m >= s.separation_m == FleetParams().separation_m


def test_one_recording_holds_every_vehicle(survey: tuple[FleetSummary, Path]) -> None:
    s, path = survey
    assert is_fleet(path)
    with RecordingReader(path) as reader:
        topics = set(reader.topics())
        meta = dict(reader.metadata)
    for k in (1, 2, 3):
        for topic in ("mission/observations", "mission/outputs", "camera/image", "vehicle/fix"):
            assert f"/uav{k}/{topic}" in topics
        assert meta[f"outcome.uav{k}"]["status"] == "completed"
    assert "/mission/observations" not in topics  # no vehicle's topics outside its namespace
    assert "/mavlink/in/HEARTBEAT" in topics  # the link's frames are shared, told by sysid
    assert meta["fleet"] == {"vehicles": "3", "offset_line": "[90.0, 10.0]"}
    assert len(json.loads(meta["crew"]["homes_en_m"])) == 3
    assert meta["outcome"]["status"] == "completed"
    assert float(meta["outcome"]["closest_approach_m"]) == pytest.approx(
        s.closest_approach_m, abs=0.01
    )
    info = summarize(path)
    assert [k for k, _ in info.vehicles] == [1, 2, 3]
    assert info.frame_count == sum(v.frames for v in s.vehicles)


def test_replay_feeds_every_member_and_finds_the_same_outputs(
    survey: tuple[FleetSummary, Path],
) -> None:
    _, path = survey
    fleet = load_fleet(path)
    results = replay_fleet(fleet)
    assert [r.identical and r.finished for r in results] == [True, True, True]
    assert sum(r.steps for r in results) == sum(len(v.steps) for v in fleet.vehicles)
    # Other parameters are a re-analysis: a wider square makes every member decide otherwise.
    denser = dataclasses.replace(
        fleet.params,
        survey=dataclasses.replace(fleet.params.survey, half_side_m=55.0),
    )
    assert isinstance(denser, FleetSurveyParams)
    assert all(r.divergence is not None for r in replay_fleet(fleet, denser))


def test_check_and_refly_from_the_command_line(survey: tuple[FleetSummary, Path]) -> None:
    _, path = survey
    result = CliRunner().invoke(cli, ["replay", "--check", str(path)])
    assert result.exit_code == 0, result.output
    assert "identical: every output of every vehicle equals the recorded one" in result.output
    assert result.output.count("; identical") == 3
    again = refly(path)
    assert again.identical, again.first_difference
    assert again.messages > 10_000


def test_the_command_flies_and_prints_the_fleet(tmp_path: Path) -> None:
    out = tmp_path / "f.mcap"
    args = ["fly", "--vehicles", "2", "--mission", "fleet-survey", "-q", "-o", str(out)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "fleet          2 vehicles, mission fleet-survey" in result.output
    assert "separation     10.00 m between vehicles 1 and 2 at the closest (kept: 5 m)" in (
        result.output
    )
    assert (
        "vehicle 1      completed" in result.output and "vehicle 2      completed" in result.output
    )
    info = CliRunner().invoke(cli, ["info", str(out)])
    assert "vehicle 2: completed" in info.output


def test_homes_given_one_by_one_are_where_the_vehicles_fly_from(tmp_path: Path) -> None:
    """``--home E,N`` once per vehicle: each boots there (its fix on the map), the recording
    keeps them, and a re-flight boots them there again, byte for byte."""
    out = tmp_path / "homes.mcap"
    homes = ((0.0, 0.0), (40.0, 18.0), (-30.0, 25.0))
    s = fly_fleet(_config(out, homes_m=homes))
    assert s.status is Status.COMPLETED, s.reason
    with RecordingReader(out) as reader:
        meta = {name: dict(record) for name, record in reader.metadata}
    crew = json.loads(meta["crew"]["homes_en_m"])
    description = FlightDescription.from_metadata(meta, source=str(out))
    assert [c for home in crew for c in home] == pytest.approx(
        [c for home in homes for c in home], abs=0.01
    )
    assert description.homes_m == homes
    again = refly(out)
    assert again.identical, again.first_difference


def test_a_viewpoint_where_another_vehicle_stands_is_planned_again() -> None:
    """Scene 61085 of the fleet benchmark: the modeller's right viewpoint, as one vehicle
    plans it, lies within the separation of the leader's home, where the leader has landed;
    the airspace would never grant it (the modeller waited out ``claim_wait_s`` and aborted,
    no model). The side photos are planned again around the other vehicles' homes."""
    scene = generate_hard_scene(
        seed=61085, options=HardOptions(spread_m=75.0, min_buildings=6, max_buildings=9)
    )
    params = with_overrides(FleetSearchParams(), {"mission.search_radius_m": 80.0})
    said: list[tuple[int, str]] = []
    s = fly_fleet(
        FlyConfig(scene=scene, params=params, no_record=True, seed=61085, offset_line=None,
                  mission="fleet-search", vehicles=3),
        progress=lambda sysid, text, _t: said.append((sysid, text)),
    )  # fmt: skip
    assert s.status is Status.COMPLETED and "model built" in s.reason, s.reason
    replanned = "a side viewpoint lies where another vehicle stands: planned again"
    assert any(text == replanned for _, text in said)  # by the modeller (vehicle 2)
    assert s.closest_approach_m >= 5.0


def _wide_fleet(
    seed: int, *, visit_all: bool = False
) -> tuple[FleetSummary, list[tuple[int, str]]]:
    """Scene ``seed`` of the fleet benchmark, flown by three vehicles (``visit_all``: every
    point of interest, by the shortest way over all, as the search did before it visited
    the target's hue first; the ways cross as they did when the scene was found)."""
    scene = generate_hard_scene(
        seed=seed, options=HardOptions(spread_m=75.0, min_buildings=6, max_buildings=9)
    )
    overrides: dict[str, object] = {"mission.search_radius_m": 80.0, "mission.visit_all": visit_all}
    params = with_overrides(FleetSearchParams(), overrides)
    said: list[tuple[int, str]] = []
    s = fly_fleet(
        FlyConfig(scene=scene, params=params, no_record=True, seed=seed, offset_line=None,
                  mission="fleet-search", vehicles=3),
        progress=lambda sysid, text, _t: said.append((sysid, text)),
    )  # fmt: skip
    return s, said


def test_two_vehicles_each_in_the_others_way_do_not_wait_for_ever() -> None:
    """Scene 61060: the helpers leave for their first looks on layers 5 m apart, each one's
    way across the other's home, where the other climbs: each waited for the other until
    both aborted. Vehicle 3 now flies around vehicle 2, which hovers on its way, and the
    fleet models the target."""
    s, said = _wide_fleet(61060, visit_all=True)
    assert s.status is Status.COMPLETED and "model built" in s.reason, s.reason
    assert any(v == 3 and ": around vehicle 2, by (" in t for v, t in said), said
    assert not any("held the way" in t for _, t in said)
    assert s.closest_approach_m >= 5.0


def test_a_vehicle_waiting_in_anothers_way_climbs_out_of_it() -> None:
    """Scene 61042: a helper waits over its last look (it found the target) right where the
    other's way across goes: the other waited until it aborted. Now the waiting one climbs
    until the other's way passes under it by the separation, and models the target."""
    s, said = _wide_fleet(61042, visit_all=True)
    assert s.status is Status.COMPLETED and "model built" in s.reason, s.reason
    assert any(v == 3 and t.startswith("giving way to vehicle 2: up to ") for v, t in said)
    assert not any("held the way" in t for _, t in said)
    assert s.closest_approach_m >= 5.0


def test_a_vehicle_that_cannot_climb_out_of_the_way_gives_way_aside() -> None:
    """Scene 61036: two points of interest 2 m apart; a helper measuring one roof low is in
    the way of the other coming down to look, which waits right above it, so it cannot climb:
    it moves aside, across at its altitude over ground it knows is clear. (Both used to wait
    until one aborted and the leader's battery failed over: pilot-takeover.) The target (b03)
    is found and modelled: the building of its colour that every look drew as the target's
    mirror image (b05, 0.61 against it, 0.90 against the mirror image) is another building,
    no doubt holding the match (it was an honest no-match while it was)."""
    s, said = _wide_fleet(61036)
    assert s.status is Status.COMPLETED, s.reason
    assert s.evaluation.matched_building == s.evaluation.target_building == "b03"
    assert any("the target's mirror image, scored" in t for _, t in said)
    aside = [t for _, t in said if t.startswith("giving way to vehicle ") and ": aside to " in t]
    assert aside, said  # vehicle 2 to vehicle 3 (the other way round before the target's hue
    # was visited first)
    assert not any("held the way" in t for _, t in said)
    assert s.closest_approach_m >= 5.0


def test_homes_closer_than_the_claims_take_off_one_after_another() -> None:
    # 8.5 m apart: more than the separation, less than two take-off columns with their
    # margins (5 + 2 × 1.5 + 2 × 0.6 m), so the second waits for the first to reach its layer.
    events: list[tuple[int, str]] = []
    s = fly_fleet(
        _config(None, vehicles=2, offset_line=(90.0, 8.5)),
        progress=lambda sysid, text, _t: events.append((sysid, text)),
    )
    assert s.status is Status.COMPLETED, s.reason
    assert (2, "take-off: waiting for vehicle 1 to clear the way") in events
    assert s.closest_approach_m >= 5.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--vehicles", "3"], "mission 'search' flies one vehicle"),
        (["--vehicles", "3", "--mission", "fleet-survey", "--connect", "tcp:127.0.0.1:1"],
         "with one --connect: give one --connect URL per vehicle"),
        (["--vehicles", "3", "--mission", "fleet-survey", "--offset-line", "90,4"],
         "the homes stand closer than the fleet's separation (5 m)"),
        (["--vehicles", "3", "--mission", "fleet-survey", "--offset-line", "0,10"],
         "vehicle 2's home 50.064790,19.945000 is in building 'purple'"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--offset-line", "90"],
         "offset line '90'"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--rerun", "x.rrd"],
         "--rerun with a fleet"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--camera", "opencv:0"],
         "--camera opencv:0 with a fleet"),
        (["--mission", "fleet-survey", "--home", "0,0"], "--home places a fleet's vehicles"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--home", "0,0"],
         "--home given 1 times for 2 vehicles"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--home", "0,0", "--home", "20,0",
          "--offset-line", "90,20"], "--home and --offset-line both place the vehicles"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--home", "0,0", "--home", "0,10"],
         "--home 0,10 (vehicle 2): 0.0 m from a building"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--home", "0,0", "--home", "3,0"],
         "vehicles 1 and 2 stand 3.0 m apart"),
        (["--vehicles", "2", "--mission", "fleet-survey", "--home", "0,0", "--home", "1e9,0"],
         "--home E=1e9: expected a finite number in [-10000, 10000]"),
    ],
)  # fmt: skip
def test_bad_fleets_are_refused_on_the_ground(
    args: list[str], message: str, tmp_path: Path
) -> None:
    out = tmp_path / "never.mcap"
    result = CliRunner().invoke(cli, ["fly", *args, "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_fleet_mission_on_one_vehicle_is_a_fleet_of_one(tmp_path: Path) -> None:
    out = tmp_path / "one.mcap"
    result = CliRunner().invoke(cli, ["fly", "--mission", "fleet-survey", "-q", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert not is_fleet(out)
    check = CliRunner().invoke(cli, ["replay", "--check", str(out)])
    assert check.exit_code == 0 and "identical" in check.output


def test_the_pytest_helpers_take_a_fleet_and_name_the_vehicle_that_differs(
    survey: tuple[FleetSummary, Path],
) -> None:
    """A fleet's recording is a golden like any other (``uavtool.testing``): identical as
    flown, and a different mission's outputs are a failure that names the vehicle."""
    _, path = survey
    assert_replays_identically(path)
    assert_reflies_identically(path)
    with pytest.raises(AssertionError, match=r"fleet\.mcap: uav1: .*'arming in GUIDED \(louder\)'"):
        assert_replays_identically(path, mission=f"{__name__}:LouderSurvey")


class LouderSurvey(FleetSurveyMission):
    """The survey, every event it says with one more word: its outputs differ from the start."""

    def event(self, level: Level, text: str) -> None:
        super().event(level, f"{text} (louder)")


def test_a_fleet_recording_is_refused_where_it_is_not_supported(
    survey: tuple[FleetSummary, Path], tmp_path: Path
) -> None:
    _, path = survey
    result = CliRunner().invoke(cli, ["replay", str(path), "-o", str(tmp_path / "r.mcap")])
    assert result.exit_code == 2 and "-o/--output and --vision-only not yet" in result.output
    with pytest.raises(InputError, match="a fleet's recording"):
        load_flight(path)


@pytest.fixture(scope="module")
def search(tmp_path_factory: pytest.TempPathFactory) -> tuple[FleetSummary, Path, list[str]]:
    path = tmp_path_factory.mktemp("fleet-search") / "search.mcap"
    said: list[str] = []
    summary = fly_fleet(
        FlyConfig(mission="fleet-search", vehicles=3, record=path),
        progress=lambda sysid, text, _t: said.append(f"{sysid}: {text}"),
    )
    return summary, path, said


def test_a_fleet_finds_and_models_the_target_apart(
    search: tuple[FleetSummary, Path, list[str]],
) -> None:
    s, _, said = search
    assert s.status is Status.COMPLETED, s.reason
    e = s.evaluation
    assert e is not None and e.matched_building == e.target_building == "red"
    assert e.model_iou is not None and e.model_iou > 0.8
    assert s.closest_approach_m >= s.separation_m
    # The helpers looked at points of interest for the leader; one of them, at the target,
    # built the model while the leader landed.
    assert any(": looking at it for vehicle 1" in line for line in said if line[0] in "23")
    modeller = [v for v in s.vehicles if v.outcome.reason == "model built for vehicle 1"]
    assert len(modeller) == 1 and modeller[0].sysid in (2, 3)
    # The other helper took one of the side photos at the same time, and handed it over
    # before the model was built from it.
    side = [v for v in s.vehicles if v.outcome.reason == "took a side photo for the model"]
    assert len(side) == 1 and {side[0].sysid, modeller[0].sysid} == {2, 3}
    m, h = modeller[0].sysid, side[0].sysid
    handed = [line for line in said if line.startswith(f"{m}: vehicle {h} takes the ")]
    assert len(handed) == 1, said
    name = handed[0].split(" takes the ")[1].split()[0]
    assert name in ("front", "right")
    assert not any("brought no photo" in line for line in said)
    landing = said.index(next(x for x in said if x.startswith("1: landing")))
    assert said.index(handed[0]) < landing  # the leader stays up until the photo is in
    assert s.vehicles[0].outcome.reason == "model built" and s.vehicles[0].outcome.model_built
    assert not any(v.outcome.status is Status.CRASHED for v in s.vehicles)


def test_a_fleets_search_replays_and_reflies_identically(
    search: tuple[FleetSummary, Path, list[str]],
) -> None:
    _, path, _ = search
    results = replay_fleet(load_fleet(path))
    assert all(r.identical and r.finished for r in results)
    again = refly(path)
    assert again.identical, again.first_difference


def test_a_search_fleet_of_one_decides_as_the_search() -> None:
    one = fly(FlyConfig(no_record=True))
    alone = fly(FlyConfig(mission="fleet-search", no_record=True))
    a, b = one.outcome, alone.outcome
    assert (a.status, a.visited, a.matched_poi, a.model_built) == (
        b.status, b.visited, b.matched_poi, b.model_built,
    )  # fmt: skip
    assert one.vehicle_time_s == alone.vehicle_time_s


def test_export_takes_each_vehicles_frames_and_the_model_out(
    search: tuple[FleetSummary, Path, list[str]], tmp_path: Path
) -> None:
    s, path, _ = search
    frames = tmp_path / "frames"
    result = CliRunner().invoke(
        cli, ["export", str(path), "--frames", str(frames), "--model", str(tmp_path / "m.glb")]
    )
    assert result.exit_code == 0, result.output
    for v in s.vehicles:
        pngs = sorted((frames / f"uav{v.sysid}").glob("frame_*.png"))
        assert len(pngs) == v.frames
    assert (tmp_path / "m.glb").read_bytes()[:4] == b"glTF"


def test_view_shows_every_vehicle_of_the_fleet(
    search: tuple[FleetSummary, Path, list[str]], tmp_path: Path
) -> None:
    s, path, _ = search
    out = tmp_path / "v.rrd"
    result = CliRunner().invoke(cli, ["view", str(path), "--save", str(out)])
    assert result.exit_code == 0, result.output
    frames = sum(v.frames for v in s.vehicles)
    assert result.output.startswith(f"wrote {out}: 3 vehicles, {frames} frames, ")


def test_export_writes_a_layout_with_a_tab_for_every_vehicle(
    search: tuple[FleetSummary, Path, list[str]], tmp_path: Path
) -> None:
    """(The fleet's layout itself: tests/recording/test_foxglove_layout.py.)"""
    s, path, _ = search
    out = tmp_path / "l.json"
    result = CliRunner().invoke(cli, ["export", str(path), "--layout", str(out)])
    assert result.exit_code == 0, result.output
    tabs = json.loads(out.read_text())["configById"]["Tab!vehicles"]["tabs"]
    assert [t["title"] for t in tabs] == [f"uav{v.sysid}" for v in s.vehicles]


def test_a_fleet_of_external_vehicles_flies_on_the_wall_clock(tmp_path: Path) -> None:
    """Three vehicles served as ArduPilot's -I instances are (``uavtool sitl --vehicles 3``),
    each on a TCP port of its own, flown with ``--connect`` three times: the same fleet mission
    on the wall clock, its closest approach from the telemetry, one recording that replays."""
    from uavtool.geo import GeoPoint
    from uavtool.sitl import SitlConfig
    from uavtool.sitl.fleet import Fleet, OffsetLine, fleet_configs, line_homes

    mount = (("MNT1_TYPE", 1.0), ("SERVO9_FUNCTION", 7.0), ("SERVO10_FUNCTION", 6.0))
    home = GeoPoint(50.0647, 19.945, 219.0)
    base = SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20.0, params=mount, home=home)
    out = tmp_path / "ext.mcap"
    with Fleet(fleet_configs(base, line_homes(home, 3, OffsetLine()))) as fleet:
        connects = tuple(f"tcp:127.0.0.1:{v.ports[0]}" for v in fleet.vehicles)
        s = fly_fleet(FlyConfig(mission="fleet-survey", connects=connects, record=out))
        assert not any(v.crashed for v in fleet.vehicles)
    assert s.status is Status.COMPLETED, s.reason
    assert not s.lockstep and [v.sysid for v in s.vehicles] == [1, 2, 3]
    assert s.separation_m <= s.closest_approach_m < 12.0  # homes 10 m apart
    with RecordingReader(out) as reader:
        meta = dict(reader.metadata)
    assert meta["vehicle"]["clock"] == "wall" and meta["vehicle"]["connect"] == " ".join(connects)
    assert all(r.identical for r in replay_fleet(load_fleet(out)))
