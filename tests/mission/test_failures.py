"""Every way the flight can go wrong: refused and unanswered commands, a vehicle that never
arrives, a pilot taking over, the link going quiet; and driving the mission wrongly."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import pytest

from tests.mission import scenes
from tests.mission.driver import (
    NO_ACK,
    At,
    Flight,
    Flown,
    LinkOutage,
    PilotMode,
    Stuck,
    assert_home_safely,
    fly,
    target_rgb,
)
from tests.mission.fakes import DENIED, REFUSED, command_key
from uavtool.mission import (
    Arm,
    Command,
    GoTo,
    LinkLost,
    LinkRestored,
    MissionInputError,
    MissionInputs,
    MissionStateError,
    ModelBuilt,
    Params,
    Photo,
    Plan,
    SearchMission,
    SetMode,
    Status,
    Takeoff,
    TakePhoto,
    Telemetry,
    Viewpoints,
)
from uavtool.mission.base import MissionEnd
from uavtool.world import Scene


def _sent_ms(flight: Flight, kind: str) -> list[int]:
    """Vehicle times at which commands of ``kind`` (see command_key) were issued."""
    return [
        step.time_ms
        for step in flight.steps
        for o in step.outputs
        if isinstance(o, Command) and command_key(o) == kind
    ]


def _commands(outputs: Sequence[object]) -> list[Command]:
    return [o for o in outputs if isinstance(o, Command)]


# --- commands refused, unanswered, moves that never arrive --------------------------------------


@pytest.mark.parametrize("kind", ["Takeoff", "SetGimbal"])
@pytest.mark.parametrize("answer", ["refuse", "ignore"])
def test_command_failing_four_times_aborts_with_rtl(paper: Scene, kind: str, answer: str) -> None:
    """Refused (COMMAND_ACK not accepted) or unanswered (the runner's ACK timeout) four times:
    the mission gives up and watches the vehicle land: in the air it sends RTL; still on the
    ground (a take-off refused: say, an obstacle above) LAND, which disarms it where it is,
    where RTL would climb into what the take-off was refused for."""
    always = {kind: 10**6}
    flown = fly(paper, refuse=always) if answer == "refuse" else fly(paper, ignore=always)
    detail = REFUSED if answer == "refuse" else NO_ACK
    outcome = flown.outcome
    assert outcome.status is Status.ABORTED
    assert outcome.reason.endswith(f"failed 4 times: {detail}")
    sent = _sent_ms(flown.flight, kind)
    assert len(sent) == 4
    p = flown.mission.params.mission
    wait_ms = p.retry_wait_s * 1000 + (0 if answer == "refuse" else 3000)
    assert all(b - a >= wait_ms for a, b in itertools.pairwise(sent))
    warnings = [t for t in flown.flight.texts() if t.endswith(" of 4)")]
    assert [w.split("(attempt ")[1] for w in warnings] == [f"{k} of 4)" for k in range(1, 5)]
    modes = [c.mode for c in flown.flight.of_type(SetMode)]
    assert modes == (["GUIDED", "LAND"] if kind == "Takeoff" else [*modes[:-1], "RTL"])
    assert_home_safely(flown)
    if kind == "Takeoff":
        assert (
            max(o.pos_enu_m[2] for o in flown.flight.observations if isinstance(o, Telemetry)) == 0
        )


@pytest.mark.parametrize("kind", ["Takeoff", "SetGimbal"])
def test_a_command_refused_for_good_is_not_asked_again(paper: Scene, kind: str) -> None:
    """MAV_RESULT_DENIED says that asking again will not work (an obstacle above home, a
    command invalid as given): the mission ends at once, with the vehicle's answer as its
    reason, and brings the vehicle down as after any abort (LAND on the ground, RTL in the
    air)."""
    flown = fly(paper, deny=frozenset({kind}))
    what = "take-off to 45 m" if kind == "Takeoff" else "gimbal to -90°"
    assert flown.outcome.status is Status.ABORTED
    assert flown.outcome.reason == f"{what}: {DENIED}"
    assert len(_sent_ms(flown.flight, kind)) == 1
    assert not [t for t in flown.flight.texts() if "(attempt " in t]
    modes = [c.mode for c in flown.flight.of_type(SetMode)]
    assert modes[-1] == ("LAND" if kind == "Takeoff" else "RTL")
    assert_home_safely(flown)


def test_transient_refusals_and_silence_are_retried(paper: Scene) -> None:
    """Pre-arm checks failing for a while, a lost ACK, a gimbal refused 3 of 4 times."""
    flown = fly(paper, refuse={"Arm": 5, "SetGimbal": 3}, ignore={"Takeoff": 1})
    assert flown.outcome.status is Status.COMPLETED and flown.outcome.model_built
    assert len(flown.flight.of_type(Arm)) == 6
    assert len(flown.flight.of_type(Takeoff)) == 2
    assert f"take-off to 45 m: {NO_ACK} (attempt 1 of 4)" in flown.flight.texts()
    assert f"gimbal to -90°: {REFUSED} (attempt 3 of 4)" in flown.flight.texts()


def test_arming_refused_for_too_long_aborts_on_the_ground(paper: Scene) -> None:
    flown = fly(paper, refuse={"Arm": 10**6})
    outcome = flown.outcome
    assert outcome.status is Status.ABORTED
    assert outcome.reason == f"arming refused for 60 s: {REFUSED}"
    end_ms = flown.flight.steps[-1].time_ms
    assert 60_000 <= end_ms <= 65_000
    # never armed, so nothing to bring home: no take-off, no RTL
    assert not flown.flight.of_type(Takeoff)
    assert [c.mode for c in flown.flight.of_type(SetMode)] == ["GUIDED"]
    assert flown.flight.texts()[-1] == "landed and disarmed"


def test_rtl_unanswered_while_finishing_still_reports(paper: Scene) -> None:
    flown = fly(paper, ignore={"SetGimbal": 10**6, "SetMode:RTL": 10**6})
    outcome = flown.outcome
    assert outcome.status is Status.ABORTED and "gimbal" in outcome.reason
    assert f"while finishing: mode RTL failed 4 times: {NO_ACK}" in flown.flight.texts()
    assert len(flown.flight.of_type(SetMode)) == 1 + 4  # GUIDED, then RTL four times


def test_move_never_arriving_is_retried_then_aborts(paper: Scene) -> None:
    """Taken off, the vehicle never moves again: the climb to the second overview photo is
    sent four times, each after its timeout, then the mission aborts."""
    flown = fly(paper, stuck=True)
    flight = flown.flight
    outcome = flight.outcome
    assert outcome.status is Status.ABORTED
    assert outcome.reason.endswith("position never reached")
    assert outcome.visited == ()
    assert not flight.of_type(Plan)
    p = flown.mission.params.mission
    high = max(g.pos_enu_m[2] for g in flight.of_type(GoTo))  # the second overview photo's
    goals = [g for g in flight.of_type(GoTo) if g.pos_enu_m[2] == high]
    assert len(goals) == 4
    sent = _sent_ms(flight, "GoTo")[-4:]
    slack_ms = p.move_slack_s * 1000
    assert all(b - a >= slack_ms for a, b in itertools.pairwise(sent))
    assert sum("not reached in" in t for t in flight.texts()) == 4
    assert_home_safely(flown)  # RTL still flies home: only GUIDED targets are ignored


def test_a_way_home_that_cannot_be_flown_is_no_success(paper: Scene) -> None:
    """Model built, then the vehicle stops following GUIDED targets: the way home over the
    roofs is tried (and retried) only, then the vehicle's RTL brings it down, and the outcome
    is 'aborted' with that reason, not 'completed'."""
    flown = fly(paper, script=(Stuck(At(after=ModelBuilt)),))
    outcome = flown.outcome
    assert outcome.status is Status.ABORTED and outcome.model_built
    assert outcome.reason == (
        f"the way home: home: across at {flown.mission.transit_m:.1f} m: position never "
        "reached; landed by RTL, after 'completed: model built'"
    )
    texts = flown.flight.texts()
    assert texts[-1] == f"mission ends: aborted: {outcome.reason}"
    assert "landed and disarmed" in texts
    assert flown.fake.landed and not flown.fake.armed
    assert flown.flight.of_type(SetMode)[-1].mode == "RTL"


def test_take_off_accepted_but_never_climbing_aborts(paper: Scene) -> None:
    flown = fly(paper, climb_m_s=0.0)
    assert flown.outcome.status is Status.ABORTED
    assert flown.outcome.reason == "take-off: 45 m never reached"
    assert_home_safely(flown)


def test_a_take_off_that_never_leaves_the_ground_is_no_crash(paper: Scene) -> None:
    """The vehicle accepts the take-off but never climbs, and its autopilot disarms it on the
    ground after 2 s (as PX4 did once under load): the flight never left home, so it is
    aborted, not crashed. (A disarm after the climb is a crash: tests/runner/test_fly.py.)"""
    flown = fly(paper, climb_m_s=0.0, disarm_on_ground_s=2.0)
    assert flown.outcome.status is Status.ABORTED
    assert flown.outcome.reason == (
        "the vehicle disarmed on the ground at 0.0 m: the take-off never left it"
    )
    assert flown.flight.texts()[-1] == "landed and disarmed"
    assert not [c for c in _commands(flown.flight.outputs) if isinstance(c, GoTo)]


def test_gimbal_never_reporting_its_pitch_warns_and_photographs_anyway(paper: Scene) -> None:
    """A gimbal that reports another pitch than commanded: the mission waits, warns and takes
    the photo at the reported pose (here: looking at the horizon, so it sees no roof)."""
    flown = fly(paper, gimbal_rate_deg_s=0.0)
    texts = flown.flight.texts()
    assert "gimbal did not report -90°; photo anyway" in texts
    photos = [o for o in flown.flight.observations if isinstance(o, Photo)]
    assert [o.tag for o in photos] == ["overview", "overview-2"]
    assert all(o.pose.pitch_deg == 0.0 for o in photos)
    assert flown.outcome.status is Status.NO_MATCH
    assert_home_safely(flown)


def test_already_flying_takes_control_in_guided(paper: Scene) -> None:
    flown = fly(paper, airborne=(3.0, -2.0, 30.0))
    assert flown.flight.texts()[0] == "already flying: taking control in GUIDED"
    assert not flown.flight.of_type(Arm) and not flown.flight.of_type(Takeoff)
    assert flown.outcome.status is Status.COMPLETED
    assert_home_safely(flown)


# --- someone else flies ----------------------------------------------------------------------


@pytest.mark.parametrize("after", [Plan, Viewpoints])
@pytest.mark.parametrize("pilot_lands", [True, False])
def test_pilot_takeover_stops_all_commands(paper: Scene, after: type, pilot_lands: bool) -> None:
    script: tuple[PilotMode, ...] = (PilotMode(At(after=after), "LOITER"),)
    if pilot_lands:
        script += (PilotMode(At(after=after, delay_s=5.0), "LAND"),)
    land_timeout_s = 120.0  # LAND from the 97 m overview at the fake's 1 m/s takes ~97 s
    flown = fly(paper, scenes.with_mission(land_timeout_s=land_timeout_s), script=script)
    flight = flown.flight
    assert flight.outcome.status is Status.TAKEOVER
    assert flight.outcome.reason == "mode changed to LOITER by the pilot or a failsafe"
    seen = next(
        i
        for i, s in enumerate(flight.steps)
        if isinstance(s.observation, Telemetry) and s.observation.mode == "LOITER"
    )
    assert _commands(flight.outputs_from(seen)) == []
    # what was done before the takeover is still reported
    if after is Plan:
        assert flight.outcome.visited == () and flight.outcome.matched_poi == -1
    else:
        assert flight.outcome.visited and flight.outcome.matched_poi >= 0
    texts = flight.texts()
    assert "no more commands; watching until the vehicle lands" in texts
    if pilot_lands:
        assert texts[-1] == "landed and disarmed"
        assert flown.fake.landed and not flown.fake.armed
    else:
        assert texts[-1] == "still flying when the mission stopped watching"
        end_ms = flight.steps[-1].time_ms
        assert end_ms - flight.steps[seen].time_ms == pytest.approx(land_timeout_s * 1000, abs=200)


def test_a_mode_the_autopilot_picks_while_parked_on_the_ground_is_no_takeover(
    paper: Scene,
) -> None:
    """A fleet's leader lands mid-mission and waits, disarmed, while another vehicle builds
    the model. PX4 picks its own mode on the ground after a while (Hold, AUTO.LOITER): nobody
    took over (a three-PX4 fleet ended "pilot-takeover" so). Armed again, a mode the mission
    did not ask for is a takeover."""
    mission = SearchMission(Params(), MissionInputs(target_rgb(paper)))
    mission._expected_modes = frozenset({"GUIDED", "LAND"})
    mission._parked = True  # as `land` leaves it

    def seen(armed: bool) -> Telemetry:
        return Telemetry(
            330_000, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, "AUTO.LOITER", armed, True, 0.0, 0.0, 90
        )

    mission._check_mode(seen(armed=False))
    with pytest.raises(MissionEnd) as ended:
        mission._check_mode(seen(armed=True))
    assert ended.value.status is Status.TAKEOVER


# --- the link goes quiet ---------------------------------------------------------------------


@pytest.mark.parametrize("when", ["searching", "overview photo"])
def test_brief_link_loss_waits_and_resumes(paper: Scene, when: str) -> None:
    """6 s of silence: the mission commands nothing until the link is back, then carries on.
    An outage starting with the overview photo swallows the first GoTo: the move is retried."""
    at = At(after=Plan) if when == "searching" else At(after=TakePhoto)
    flown = fly(paper, script=(LinkOutage(at, 6.0),))
    flight = flown.flight
    assert flight.outcome.status is Status.COMPLETED and flight.outcome.model_built
    assert [o.silent_s for o in flight.observations if isinstance(o, LinkLost)] == [3.0, 4.0, 5.0]
    assert [o.silent_s for o in flight.observations if isinstance(o, LinkRestored)] == [6.0]
    lost, back = flight.first_step(LinkLost), flight.first_step(LinkRestored)
    assert _commands([o for s in flight.steps[lost : back + 1] for o in s.outputs]) == []
    texts = flight.texts()
    assert any(t.startswith("link lost (3.0 s of silence): waiting") for t in texts)
    assert "link restored after 6.0 s" in texts
    assert any("not reached in" in t for t in texts) is (when == "overview photo")
    assert_home_safely(flown)


def test_failsafe_during_link_loss_ends_the_mission_without_commands(paper: Scene) -> None:
    outage = LinkOutage(At(after=Plan), 10.0, failsafe_mode="RTL", failsafe_after_s=5.0)
    flown = fly(paper, script=(outage,))
    flight = flown.flight
    assert flight.outcome.status is Status.LINK_LOST
    assert flight.outcome.reason == "mode changed to RTL by the vehicle's failsafe"
    assert _commands(flight.outputs_from(flight.first_step(LinkLost))) == []
    # it ends on the first telemetry after the link is back: the failsafe flies from here
    last = flight.observations[-1]
    assert isinstance(last, Telemetry) and last.mode == "RTL"
    assert isinstance(flight.observations[-2], LinkRestored)


@pytest.mark.parametrize(("abort_s", "failsafe"), [(30.0, None), (30.0, "RTL"), (10.0, None)])
def test_link_lost_too_long_ends_the_mission(
    paper: Scene, abort_s: float, failsafe: str | None
) -> None:
    outage = LinkOutage(At(after=Plan), 120.0, failsafe_mode=failsafe)
    flown = fly(paper, scenes.with_mission(link_lost_abort_s=abort_s), script=(outage,))
    flight = flown.flight
    assert flight.outcome.status is Status.LINK_LOST
    assert flight.outcome.reason == f"no link for {abort_s + 1:.0f} s"
    last = flight.observations[-1]
    assert isinstance(last, LinkLost) and last.silent_s == abort_s + 1.0
    assert _commands(flight.outputs_from(flight.first_step(LinkLost))) == []


def test_pilot_takeover_after_a_restored_link_is_a_takeover(paper: Scene) -> None:
    """Once the link is back and the mission has resumed, a later mode change is someone
    else's doing, not the link-loss failsafe's: TAKEOVER, and the landing is watched."""
    script = (
        LinkOutage(At(after=Plan), 6.0),
        PilotMode(At(after=Viewpoints), "LOITER"),
        PilotMode(At(after=Viewpoints, delay_s=5.0), "LAND"),
    )
    flown = fly(paper, script=script)
    outcome = flown.outcome
    assert (outcome.status, outcome.reason) == (
        Status.TAKEOVER,
        "mode changed to LOITER by the pilot or a failsafe",
    )
    assert flown.flight.texts()[-1] == "landed and disarmed"


# --- driving the mission wrongly -------------------------------------------------------------


def test_stepping_after_the_end_raises(paper_flight: Flown) -> None:
    mission = paper_flight.mission
    assert mission.done
    with pytest.raises(MissionStateError, match="ended"):
        mission.step(paper_flight.flight.observations[-1])
    with pytest.raises(MissionStateError, match="already started"):
        mission.start()


def test_stepping_after_an_abort_raises(paper: Scene) -> None:
    flown = fly(paper, refuse={"Takeoff": 10**6})
    with pytest.raises(MissionStateError, match="ended"):
        flown.mission.step(flown.flight.observations[-1])


def test_stepping_before_start_raises(paper: Scene) -> None:
    mission = SearchMission(Params(), MissionInputs(target_rgb(paper)))
    telemetry = Telemetry(
        100, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, "STABILIZE", False, True, 0.0, 0.0, 100
    )
    with pytest.raises(MissionStateError, match="start"):
        mission.step(telemetry)


def test_target_without_a_shape_is_an_input_error() -> None:
    grey = np.full((480, 640, 3), 128, dtype=np.uint8)
    with pytest.raises(MissionInputError, match="target image"):
        SearchMission(Params(), MissionInputs(grey))
