"""Pre-flight checks on the ground, ``--no-gimbal``, the scene placed where the vehicle is,
and the vehicle's refusals in the terminal and the summary (issue 18)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.autopilot.ardupilot import ArduPilot
from uavtool.cli import cli
from uavtool.geo import geo_from_enu
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Params, SearchMission, Status
from uavtool.mission.base import Envelope
from uavtool.mission.params import with_overrides
from uavtool.mission.scenario import NO_GIMBAL_REASON
from uavtool.plugins import ref_of
from uavtool.runner.fly import FlyConfig, describe, fly
from uavtool.runner.placement import place_scene
from uavtool.runner.preflight import (
    ANSWER_S,
    UNHEARD_S,
    PreflightError,
    check_fence,
    check_gimbal,
)
from uavtool.runner.summary import format_summary
from uavtool.world import load_scene


def test_no_mount_stops_on_the_ground_naming_the_fix(tmp_path: Path) -> None:
    said: list[str] = []
    path = tmp_path / "f.mcap"
    with pytest.raises(PreflightError) as exc:
        fly(FlyConfig(record=path, vehicle_params=(("MNT1_TYPE", 0.0),)), status=said.append)
    text = str(exc.value)
    assert "no gimbal" in text and "MNT1_TYPE=1" in text and "reboot" in text
    assert "--no-gimbal" in text
    assert not path.exists()  # nothing flew: no recording is left


def test_no_mount_is_exit_2_with_one_line() -> None:
    result = CliRunner().invoke(cli, ["fly", "--no-record", "-q", "--param", "MNT1_TYPE=0"])
    assert result.exit_code == 2
    assert len(result.output.strip().splitlines()) == 1


def test_an_altitude_fence_below_the_second_overview_stops_on_the_ground(tmp_path: Path) -> None:
    """ArduCopter's default FENCE_ALT_MAX (100 m), switched on, is below the 117.4 m the second
    overview climbs to (the search square at the tallest expected roof): the run stops before
    arming with the fix; a fence above it, or a lower search square, flies."""
    path = tmp_path / "f.mcap"
    fence = (("FENCE_ENABLE", 1.0),)
    with pytest.raises(PreflightError) as exc:
        fly(FlyConfig(record=path, vehicle_params=fence))
    text = str(exc.value)
    assert "FENCE_ALT_MAX=100 m" in text and "117.4 m" in text and "set FENCE_ALT_MAX=123" in text
    assert not path.exists()
    high = fly(FlyConfig(no_record=True, vehicle_params=(*fence, ("FENCE_ALT_MAX", 123.0))))
    assert high.outcome.status == Status.COMPLETED
    low = with_overrides(
        Params(), {"mission.search_radius_m": "30", "mission.assumed_roof_m": "20"}
    )
    assert fly(FlyConfig(no_record=True, params=low, vehicle_params=fence)).outcome.status == (
        Status.COMPLETED
    )


def test_a_circle_fence_inside_the_search_square_stops_on_the_ground(tmp_path: Path) -> None:
    """FENCE_RADIUS 50 m is inside the ±40 m search square (its corners 56.6 m out)."""
    circle = (("FENCE_ENABLE", 1.0), ("FENCE_ALT_MAX", 150.0), ("FENCE_RADIUS", 50.0))
    with pytest.raises(PreflightError) as exc:
        fly(FlyConfig(record=tmp_path / "f.mcap", vehicle_params=circle))
    assert "FENCE_RADIUS=50 m" in str(exc.value) and "56.6 m from home" in str(exc.value)
    only_altitude = (*circle, ("FENCE_TYPE", 1.0))  # the circle is not in force
    assert fly(FlyConfig(no_record=True, vehicle_params=only_altitude)).outcome.status == (
        Status.COMPLETED
    )


def test_no_gimbal_flies_the_search_and_ends_partial(tmp_path: Path) -> None:
    summary = fly(FlyConfig(record=tmp_path / "f.mcap", no_gimbal=True))
    o = summary.outcome
    assert o.status == Status.PARTIAL
    assert o.reason == NO_GIMBAL_REASON
    assert summary.evaluation.matched_building == "red"
    assert not o.model_built


def test_a_vehicle_that_refuses_is_heard_and_summarised(monkeypatch: pytest.MonkeyPatch) -> None:
    """A mount type set at run time on a vehicle that booted without one: ArduCopter's
    "Arm: Mount: check TYPE" is printed as it arrives and repeated in the summary."""
    monkeypatch.setattr("uavtool.runner.backends.BOOT_ONLY_PARAMS", frozenset())  # set after boot
    heard: list[str] = []
    config = FlyConfig(
        no_record=True,
        no_gimbal=True,
        params=with_overrides(Params(), {"mission.arm_wait_s": "3"}),
        vehicle_params=(("MNT1_TYPE", 1.0),),
    )
    summary = fly(config, vehicle_says=heard.append)
    assert summary.outcome.status == Status.ABORTED
    assert any("Arm: Mount: check TYPE" in h for h in heard)
    assert "Arm: Mount: check TYPE" in summary.last_refusal
    assert "COMPONENT_ARM_DISARM" in summary.last_refusal
    lines = format_summary(summary).splitlines()
    assert f"last refusal   {summary.last_refusal}" in lines
    # A flight that got past a refusal (arming retried) mentions it as such.
    went_on = replace(summary, outcome=replace(summary.outcome, status=Status.COMPLETED))
    assert (
        f"refused        {summary.last_refusal} (the mission retried and went on)"
        in format_summary(went_on).splitlines()
    )


def test_the_scene_goes_where_the_vehicle_is() -> None:
    scene = load_scene("paper")
    canberra = geo_from_enu(scene.home, 0.0, 252_000.0, 0.0)
    assert place_scene(scene, canberra, "vehicle", lambda _t: None) == canberra


def test_scene_origin_scene_refuses_a_far_vehicle_with_the_home_to_use() -> None:
    scene = load_scene("paper")
    far = geo_from_enu(scene.home, 0.0, 252_000.0, 0.0)
    with pytest.raises(PreflightError) as exc:
        place_scene(scene, far, "scene", lambda _t: None)
    assert "252.0 km" in str(exc.value)
    assert f"--home {scene.home.lat_deg:.7f},{scene.home.lon_deg:.7f}" in str(exc.value)
    near = geo_from_enu(scene.home, 5.0, 0.0, 0.0)
    assert place_scene(scene, near, "scene", lambda _t: None) == scene.home


def test_the_metadata_says_which_origin() -> None:
    scene = load_scene("paper")
    origin = {
        (connect, where): describe(
            FlyConfig(connect=connect, scene_origin=where, params=Params()),
            scene,
            ref_of(SearchMission),
            has_target=True,
        ).to_metadata()["vehicle"]["scene_origin"]
        for connect in (None, "tcp:127.0.0.1:5760")
        for where in ("vehicle", "scene")
    }
    assert origin[None, "vehicle"] == "scene"  # the built-in vehicle boots at the scene's home
    assert origin["tcp:127.0.0.1:5760", "vehicle"] == "vehicle-home"
    assert origin["tcp:127.0.0.1:5760", "scene"] == "scene"


class _SilentForAWhile:
    """A link to a vehicle whose ACKs and answers are all lost until ``heard_from_s`` (on a
    clock that each poll moves on), and which answers a gimbal request with ``answer``."""

    name = "lossy"
    target_system = 1
    target_component = 1

    def __init__(
        self, heard_from_s: float, answer: object | None, params: dict[str, float] | None = None
    ) -> None:
        self.heard_from_s = heard_from_s
        self.answer = answer
        self.params = params or {}
        self.now = 0.0
        self.asked: list[float] = []
        self._out: list[object] = []

    def clock(self) -> float:
        return self.now

    def command_long(self, command: int, *_params: float) -> None:
        self.asked.append(self.now)
        if self.now >= self.heard_from_s:
            self._out.append(M.MAVLink_command_ack_message(command, M.MAV_RESULT_ACCEPTED))
            if self.answer is not None:
                self._out.append(self.answer)

    def send(self, msg: object) -> None:  # parameter reads: answered from ``params``
        raw = getattr(msg, "param_id", "")
        name = (raw.decode() if isinstance(raw, bytes) else raw).rstrip("\0")
        if self.now >= self.heard_from_s and name in self.params:
            value = M.MAVLink_param_value_message(
                name.encode(), self.params[name], M.MAV_PARAM_TYPE_REAL32, len(self.params), 0
            )
            self._out.append(value)

    def poll(self, timeout_s: float) -> list[object]:
        self.now += timeout_s
        out, self._out = self._out, []
        return out


def _gimbal(pitch_min_deg: float = -90.0) -> object:
    return M.MAVLink_gimbal_manager_information_message(
        0, 0, 1, 0.0, 0.0, math.radians(pitch_min_deg), 0.0, -math.pi, math.pi
    )


def test_a_gimbal_question_lost_for_longer_than_the_answer_window_is_asked_again() -> None:
    """A link that loses everything for 5 s (longer than ANSWER_S) is not a vehicle without
    a gimbal: the CI run that lost six questions in a row at 20 % loss said it was."""
    link = _SilentForAWhile(heard_from_s=5.0, answer=_gimbal())
    assert check_gimbal(link, ArduPilot()) == pytest.approx((-90.0, 0.0))  # type: ignore[arg-type]
    assert len(link.asked) >= 10 and link.asked[-1] >= 5.0


def test_a_vehicle_that_hears_and_sends_no_gimbal_has_none_after_the_answer_window() -> None:
    link = _SilentForAWhile(heard_from_s=1.0, answer=None)
    with pytest.raises(PreflightError, match="no gimbal"):
        check_gimbal(link, ArduPilot())  # type: ignore[arg-type]
    # ANSWER_S of gimbal requests after the first ACK, then ANSWER_S of unanswered MNT1_TYPE
    assert link.now == pytest.approx(1.0 + 2 * ANSWER_S, abs=0.2)


def test_a_vehicle_that_acknowledges_no_request_is_asked_for_longer_then_has_no_gimbal() -> None:
    link = _SilentForAWhile(heard_from_s=math.inf, answer=None)
    with pytest.raises(PreflightError, match="no gimbal"):
        check_gimbal(link, ArduPilot())  # type: ignore[arg-type]
    assert link.now == pytest.approx(UNHEARD_S + ANSWER_S, abs=0.2)


def test_a_fence_whose_parameters_are_lost_for_a_while_still_stops_on_the_ground() -> None:
    """A lossy link that loses every parameter read for 5 s (longer than ANSWER_S): the
    fence check took the silence for a vehicle without those parameters and passed a fence
    at 100 m under a mission that climbs to 117.4 m."""
    fence = {"FENCE_ENABLE": 1.0, "FENCE_TYPE": 7.0, "FENCE_ALT_MAX": 100.0, "FENCE_RADIUS": 300.0}
    link = _SilentForAWhile(heard_from_s=5.0, answer=None, params=fence)
    with pytest.raises(PreflightError, match="FENCE_ALT_MAX=100 m"):
        check_fence(link, ArduPilot(), Envelope(altitude_m=117.4))  # type: ignore[arg-type]


def test_a_vehicle_without_fence_parameters_passes_after_asking_long_enough() -> None:
    link = _SilentForAWhile(heard_from_s=0.0, answer=None)
    check_fence(link, ArduPilot(), Envelope(altitude_m=117.4))  # type: ignore[arg-type]
    assert link.now == pytest.approx(UNHEARD_S, abs=0.2)  # FENCE_ENABLE unanswered: no fence
