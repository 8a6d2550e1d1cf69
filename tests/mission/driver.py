"""The runner's part, played in pure Python: :func:`run` flies a mission on a
:class:`~tests.mission.fakes.FakeVehicle` and injects scripted events.

Like ``uavtool.runner.Runner`` it feeds the mission telemetry every 100 ms of vehicle time,
command results and photos as soon as they exist (a GoTo is answered "sent" at once),
expires unanswered commands after 3 s of vehicle time, reports LinkLost after 3 s of
silence and every second after, and LinkRestored when telemetry returns. Scripted events
(a pilot's mode change, a link outage with the vehicle's failsafe acting in it) happen at a
vehicle time, a mission step, or after the mission first emits some output.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any, TypeVar

from tests.mission.fakes import INTRINSICS, FakeVehicle
from uavtool.camera import Intrinsics
from uavtool.images import png_decode
from uavtool.mission import (
    Command,
    CommandResult,
    Event,
    GoTo,
    LinkLost,
    LinkRestored,
    MissionInputs,
    Observation,
    Outcome,
    Output,
    Params,
    SearchMission,
    SetMode,
    TakePhoto,
)
from uavtool.mission.observations import U8Array
from uavtool.runner.fly import target_picture
from uavtool.world import Scene

ACK_TIMEOUT_S = 3.0  # the runner's RunnerConfig defaults
LINK_TIMEOUT_S = 3.0
LINK_REPORT_S = 1.0
NO_ACK = f"no COMMAND_ACK in {ACK_TIMEOUT_S:g} s"

T = TypeVar("T")


@dataclass(frozen=True, slots=True)
class At:
    """When a scripted event happens: at vehicle time ``t_s``, at mission step ``step``, or
    ``delay_s`` of vehicle time after the mission's ``nth`` output of type ``after``."""

    t_s: float | None = None
    step: int | None = None
    after: type | None = None
    nth: int = 1
    delay_s: float = 0.0


@dataclass(frozen=True, slots=True)
class PilotMode:
    """Someone else (the pilot, a failsafe) switches the vehicle to ``mode``."""

    at: At
    mode: str


@dataclass(frozen=True, slots=True)
class LinkOutage:
    """Nothing passes either way for ``duration_s``. With ``failsafe_mode`` the vehicle
    switches to it ``failsafe_after_s`` into the outage (its GCS failsafe)."""

    at: At
    duration_s: float
    failsafe_mode: str | None = None
    failsafe_after_s: float = 5.0


@dataclass(frozen=True, slots=True)
class Stuck:
    """From then on the vehicle holds where it is and takes GUIDED targets but never moves
    toward them (RTL still works)."""

    at: At


Inject = PilotMode | LinkOutage | Stuck


@dataclass(frozen=True, slots=True)
class Step:
    """One call of the mission: ``observation`` (None for ``start()``) fed at vehicle time
    ``time_ms``, and what the mission answered."""

    time_ms: int
    observation: Observation | None
    outputs: tuple[Output, ...]


@dataclass(frozen=True, slots=True)
class Flight:
    """What a run produced: every output and every observation in order, and each step."""

    outputs: list[Output]
    observations: list[Observation]
    steps: list[Step]

    @property
    def outcome(self) -> Outcome:
        last = self.outputs[-1]
        assert isinstance(last, Outcome), last
        return last

    def of_type(self, cls: type[T]) -> list[T]:
        return [o for o in self.outputs if isinstance(o, cls)]

    def texts(self) -> list[str]:
        """The events' texts, in order."""
        return [o.text for o in self.outputs if isinstance(o, Event)]

    def first_step(self, kind: type) -> int:
        """Index in :attr:`steps` of the first step fed an observation of type ``kind``."""
        return next(i for i, s in enumerate(self.steps) if isinstance(s.observation, kind))

    def outputs_from(self, step: int) -> list[Output]:
        """Outputs of step ``step`` and every later one."""
        return [o for s in self.steps[step:] for o in s.outputs]


@dataclass
class _Trigger:
    at: At
    since_ms: int | None = None

    def due(self, step: int, now_ms: int, counts: dict[type, int]) -> bool:
        at = self.at
        if at.step is not None:
            return step >= at.step
        if at.t_s is not None:
            return now_ms >= at.t_s * 1000.0
        if at.after is not None and self.since_ms is None and counts.get(at.after, 0) >= at.nth:
            self.since_ms = now_ms
        return self.since_ms is not None and now_ms - self.since_ms >= at.delay_s * 1000.0


@dataclass
class _Link:
    """The runner's view of the link: silence, pending ACKs, the outage in progress."""

    outage: LinkOutage | None = None
    outage_start_ms: int = 0
    last_rx_ms: int = 0
    last_report_ms: int = 0
    reported: bool = False
    pending: dict[int, int] = field(default_factory=dict)  # action id -> ms sent

    def tick(self, fake: FakeVehicle, queue: deque[Observation]) -> None:
        """What the runner has to tell the mission after one more tick of the vehicle."""
        now = fake.time_ms
        if self.outage is not None:
            into_s = (now - self.outage_start_ms) / 1000.0
            failsafe = self.outage.failsafe_mode
            if failsafe and into_s >= self.outage.failsafe_after_s and fake.mode != failsafe:
                fake.set_mode(failsafe)
            silent_s = (now - self.last_rx_ms) / 1000.0
            if into_s >= self.outage.duration_s:
                self.outage = None
                if self.reported:
                    queue.append(LinkRestored(silent_s))
            elif silent_s >= LINK_TIMEOUT_S and (
                not self.reported or now - self.last_report_ms >= LINK_REPORT_S * 1000.0
            ):
                self.reported, self.last_report_ms = True, now
                queue.append(LinkLost(silent_s))
        if self.outage is None:
            self.last_rx_ms = now
            queue.append(fake.telemetry())
            for action_id, sent_ms in list(self.pending.items()):
                if now - sent_ms > ACK_TIMEOUT_S * 1000.0:
                    del self.pending[action_id]
                    queue.append(CommandResult(action_id, False, NO_ACK))


def run(
    mission: SearchMission,
    fake: FakeVehicle,
    *,
    script: tuple[Inject, ...] = (),
    max_steps: int = 20_000,
) -> Flight:
    """Fly ``mission`` on ``fake`` until it has an outcome, as the runner would.
    Raises AssertionError after ``max_steps`` observations without one."""
    outputs: list[Output] = []
    observations: list[Observation] = []
    steps: list[Step] = []
    queue: deque[Observation] = deque()
    counts: dict[type, int] = {}
    todo = [(_Trigger(inj.at), inj) for inj in script]
    link = _Link()

    def handle(obs: Observation | None, outs: list[Output]) -> None:
        steps.append(Step(fake.time_ms, obs, tuple(outs)))
        outputs.extend(outs)
        for out in outs:
            counts[type(out)] = counts.get(type(out), 0) + 1
            if isinstance(out, TakePhoto):
                queue.append(fake.photo(out))  # the camera is on the ground station's side
            elif isinstance(out, GoTo) and link.outage is not None:
                queue.append(CommandResult(out.id, True, "sent"))  # sent into the void
            elif isinstance(out, Command):
                answer = fake.execute(out) if link.outage is None else None
                if answer is None:
                    link.pending[out.id] = link.last_rx_ms
                else:
                    queue.append(answer)

    handle(None, mission.start())
    while mission.outcome is None:
        if len(observations) >= max_steps:
            raise AssertionError(f"no outcome after {max_steps} observations")
        for entry in list(todo):
            trigger, inj = entry
            if trigger.due(len(observations), fake.time_ms, counts):
                todo.remove(entry)
                if isinstance(inj, PilotMode):
                    fake.set_mode(inj.mode)
                elif isinstance(inj, Stuck):
                    fake.stuck, fake.goal = True, fake.pos
                else:
                    link.outage, link.outage_start_ms, link.reported = inj, fake.time_ms, False
        if not queue:
            fake.tick()
            link.tick(fake, queue)
            if not queue:
                continue
        obs = queue.popleft()
        observations.append(obs)
        handle(obs, mission.step(obs))
    return Flight(outputs, observations, steps)


def target_rgb(scene: Scene, intrinsics: Intrinsics = INTRINSICS) -> U8Array:
    """The scene's target building alone, seen from above, as ``uavtool fly`` makes it."""
    return png_decode(target_picture(scene, intrinsics), where="target")


@dataclass(frozen=True, slots=True)
class Flown:
    """A finished run: the mission, its target picture, the vehicle and what was flown."""

    mission: SearchMission
    target_rgb: U8Array
    fake: FakeVehicle
    flight: Flight

    @property
    def outcome(self) -> Outcome:
        return self.flight.outcome


def fly(
    scene: Scene,
    params: Params | None = None,
    *,
    target_scene: Scene | None = None,
    script: tuple[Inject, ...] = (),
    max_steps: int = 20_000,
    **vehicle: Any,
) -> Flown:
    """A fresh mission looking for ``target_scene``'s (default ``scene``'s) target, flown on
    a fresh vehicle in ``scene`` (``vehicle``: :class:`FakeVehicle` options)."""
    target = target_rgb(target_scene or scene)
    mission = SearchMission(params or Params(), MissionInputs(target))
    fake = FakeVehicle(scene, **vehicle)
    return Flown(mission, target, fake, run(mission, fake, script=script, max_steps=max_steps))


def assert_home_safely(flown: Flown) -> None:
    """After the mission's end it flies home over the roofs it knows (straight up, across to
    above home at the transit altitude) then commands RTL once at most, and the vehicle lands
    at home; a vehicle that never left the ground gets LAND instead (it disarms in place)."""
    flight = flown.flight
    end = next(
        i
        for i, o in enumerate(flight.outputs)
        if isinstance(o, Event) and o.text.startswith("mission ends")
    )
    after = [o for o in flight.outputs[end:] if isinstance(o, Command)]
    moves = [c for c in after if isinstance(c, GoTo)]
    modes = [c for c in after if not isinstance(c, GoTo)]
    on_ground = any(t.startswith("still on the ground") for t in flight.texts())
    landing = "LAND" if on_ground else "RTL"
    assert all(c == SetMode(c.id, landing) for c in modes) and len(modes) <= 1
    assert after[len(moves) :] == modes  # the moves come first
    transit = flown.mission.transit_m
    assert all(g.pos_enu_m[2] == transit for g in moves)
    if moves:
        assert moves[-1].pos_enu_m[:2] == (0.0, 0.0)
    assert flight.texts()[-1] == "landed and disarmed"
    fake = flown.fake
    assert fake.landed and not fake.armed
    assert math.hypot(fake.pos[0], fake.pos[1]) < 0.1
