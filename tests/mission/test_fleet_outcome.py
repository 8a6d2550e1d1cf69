"""A fleet's outcome, as its crew judges it from its members' (exit codes follow it)."""

from __future__ import annotations

from uavtool.mission import MissionInputs, Outcome, Status
from uavtool.mission.fleet import FleetParams
from uavtool.mission.fleet_search import SearchCrew


def test_a_fleet_search_that_lost_a_vehicle_does_not_pass_for_completed() -> None:
    """The leader built the model, but a helper's flight failed: the fleet's outcome is the
    failure (exit code non-zero), with what the search found beside it."""
    crew = SearchCrew(None, MissionInputs(), ((0.0, 0.0), (10.0, 0.0), (20.0, 0.0)), FleetParams())
    done = Outcome(Status.COMPLETED, "model built", model_built=True)
    ok = Outcome(Status.COMPLETED, "called off")
    assert crew.outcome([done, ok, ok]) == (Status.COMPLETED, "model built")
    lost = Outcome(Status.LINK_LOST, "no telemetry for 30 s")
    crashed = Outcome(Status.CRASHED, "Crash: collision with vehicle 2")
    assert crew.outcome([done, lost, ok]) == (
        Status.LINK_LOST,
        "vehicle 2: no telemetry for 30 s; the search: completed: model built",
    )
    status, reason = crew.outcome([done, lost, crashed])
    assert status is Status.CRASHED and reason.startswith("vehicle 3: Crash")
    aborted = Outcome(Status.ABORTED, "arming refused")
    assert crew.outcome([aborted, ok, ok]) == (Status.ABORTED, "vehicle 1: arming refused")
