"""Replay of a fleet: every member rebuilt, fed its own vehicle's recorded observations in the
fleet's one order (the step numbers the runners shared), and each member's outputs compared
with its vehicle's recorded ones, as one vehicle's replay does."""

from __future__ import annotations

import heapq
from typing import Any

from uavtool.mission import MissionInputs
from uavtool.mission.fleet import FleetMember
from uavtool.plugins import create_fleet, flight_params, guarded
from uavtool.replay.load import RecordedFleet, ReplayInputError
from uavtool.replay.replay import Comparison, Progress, ReplayResult


def replay_fleet(
    fleet: RecordedFleet, params: Any = None, *, progress: Progress | None = None
) -> list[ReplayResult]:
    """One :class:`ReplayResult` per vehicle, in system-id order."""
    if not issubclass(fleet.mission, FleetMember):
        raise ReplayInputError(
            f"{fleet.path}: mission {fleet.mission_ref.name!r} is not a fleet mission"
        )
    p = params if params is not None else fleet.params
    inputs = MissionInputs(target_rgb=fleet.target_rgb)
    members = create_fleet(fleet.mission, p, inputs, fleet.homes_en_m)
    if len(members) != len(fleet.vehicles):
        raise ReplayInputError(
            f"{fleet.path}: {len(fleet.vehicles)} vehicles, {len(members)} homes"
        )
    comparisons = [Comparison(v.outputs, flight_params(fleet.mission, p)) for v in fleet.vehicles]
    for member, cmp in zip(members, comparisons, strict=True):
        cmp.emit(0, guarded(member.start))
    queue = [(step, k, i) for k, v in enumerate(fleet.vehicles) for i, step in enumerate(v.steps)]
    heapq.heapify(queue)
    total = len(queue)
    done = 0
    while queue:
        step, k, i = heapq.heappop(queue)
        member, cmp = members[k], comparisons[k]
        if cmp.result.divergence is not None:
            continue
        if member.done:
            cmp.diverge(step, "the mission ended before the recording did")
            continue
        cmp.result.steps += 1
        cmp.emit(step, guarded(member.step, fleet.vehicles[k].observations[i]))
        done += 1
        if progress is not None and (done % 200 == 0 or done == total):
            progress(done, total)
    results = []
    for member, cmp, vehicle in zip(members, comparisons, fleet.vehicles, strict=True):
        result = cmp.result
        result.finished = member.done
        recorded = vehicle.outputs
        if result.identical and len(result.outputs) < len(recorded) and not fleet.truncated:
            cmp.missing(recorded[len(result.outputs)])
        results.append(result)
    return results
