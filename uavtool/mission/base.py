"""The base of every mission: a pure state machine that flies one generator.

A mission is written as one generator, :meth:`FlightMission.fly`, read top to bottom; each
``yield`` waits for the next observation. Observations go in (:meth:`FlightMission.step`),
outputs come out: commands for the runner to execute and results to record. A mission never
reads a clock (its time is the vehicle's ``time_boot_ms``), a socket or an unseeded random
generator, so a replay that feeds it the recorded observations reproduces every output
exactly.

What can go wrong anywhere — a command refused or unanswered, a move that never arrives,
someone else changing the mode, the link going quiet, a disarm in the air — is handled once,
in the waiting helpers, which end the flight by raising :meth:`FlightMission.end`. How a
flight ends is handled here too: the way home, RTL and the landing, and an honest
:class:`~uavtool.mission.outputs.Outcome` (a collision at any moment is ``crashed``).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

from uavtool.camera import Intrinsics
from uavtool.geo import wrap_180
from uavtool.mission.errors import MissionStateError
from uavtool.mission.observations import (
    CommandResult,
    LinkLost,
    LinkRestored,
    Observation,
    Photo,
    Telemetry,
    U8Array,
)
from uavtool.mission.outputs import (
    Arm,
    Command,
    Event,
    GoTo,
    Level,
    Outcome,
    Output,
    SetGimbal,
    SetMode,
    Status,
    Takeoff,
    TakePhoto,
    Vec3,
)
from uavtool.mission.params import FlightParams

T = TypeVar("T")
Wait = Generator[None, Observation, T]
"""A step that waits for observations and finally returns a ``T``."""

NADIR_DEG = -90.0
HORIZONTAL_DEG = 0.0


class MissionEnd(Exception):  # noqa: N818 - control flow inside the generator, never escapes
    """Ends the flight with a status and its reason: ``raise self.end(status, reason)``."""

    def __init__(self, status: Status, reason: str) -> None:
        super().__init__(reason)
        self.status = status
        self.reason = reason


@dataclass(frozen=True, slots=True)
class MissionInputs:
    """What a flight gives a mission besides its parameters. ``target_rgb`` : (H, W, 3) uint8,
    the target picture, for a mission that declares ``needs_target`` (else None)."""

    target_rgb: U8Array | None = None


@dataclass(frozen=True, slots=True)
class Envelope:
    """Where a mission will fly, known before the flight, so that a vehicle whose geofence
    would stop it is refused on the ground: ``altitude_m`` above home at most (``why_up``
    says what for), ``distance_m`` from home at most (``why_out``), and which parameters
    shrink either (``shrink_up``, ``shrink_out``: the words of the fix)."""

    altitude_m: float | None = None
    distance_m: float | None = None
    why_up: str = ""
    why_out: str = ""
    shrink_up: str = ""
    shrink_out: str = ""


_HOME_HEIGHT_TOLERANCE_M = 2.0
"""How far from home's height a vehicle that landed and disarmed after RTL may report itself:
more than an altimeter drifts in a flight, less than a storey (a roof is no landing)."""
_FLIES_HOME = frozenset({Status.COMPLETED, Status.PARTIAL, Status.NO_MATCH})
"""Outcomes after which the mission still flies its way home itself before RTL."""


class FlightMission:
    """One flight of a mission. The runner calls :meth:`start` once, then :meth:`step` with
    each observation until :attr:`done`; the last output is the :class:`Outcome`.

    Subclass it, declare its parameters type (``params_type``: a frozen dataclass of groups,
    one of them a :class:`FlightParams` named by ``flight_group``) and write :meth:`fly` with
    the helpers below (:meth:`arm_and_take_off`, :meth:`move`, :meth:`photo`,
    :meth:`wait_until`, :meth:`event`, :meth:`emit`, …). uavtool builds it as
    ``Class(params, inputs)``; the parameters are :attr:`params`, the flight's inputs
    :attr:`inputs`.
    """

    name: ClassVar[str] = ""
    """The name a recording gives the mission when it is not registered under one."""
    params_type: ClassVar[type[Any]] = type(None)
    """The parameters type: a frozen dataclass whose fields are groups of values."""
    needs_target: ClassVar[bool] = False
    """Whether the flight must give a target picture (``MissionInputs.target_rgb``)."""
    go_home_after: ClassVar[frozenset[Status]] = _FLIES_HOME
    """The outcomes after which :meth:`go_home` flies the way home before RTL (a fleet's
    members fly it after an abort too: their RTL must keep clear of the others)."""
    flight_group: ClassVar[str] = "flight"
    """The group of ``params_type`` that is the :class:`FlightParams` (``--no-gimbal`` sets its
    ``gimbal``)."""

    def __init__(self, params: Any, inputs: MissionInputs | None = None) -> None:
        self.params = params
        self.inputs = inputs or MissionInputs()
        self.flight: FlightParams = getattr(params, self.flight_group)
        """How it flies: arrival tolerances, timeouts, retries, whether it has a gimbal."""
        self.outcome: Outcome | None = None
        self.last: Telemetry | None = None
        """The newest telemetry (None before the first)."""
        self._out: list[Output] = []
        self._next_id = 0
        self._expected_modes: frozenset[str] = frozenset()
        self._link_was_lost = False
        self._airborne = False  # from take-off until landed: disarming in the air is a crash
        self._left_ground = False  # seen above home's height tolerance since the take-off
        self._landing = False  # RTL or LAND sent: a disarm on the ground at home is the landing
        self._parked = False  # landed and disarmed mid-mission, until the next take-off
        self._deferred: list[Observation] = []
        self._in_fly = False  # fly() is running: interrupt() may end it
        self._gen = self._run()
        self._started = False

    # --- what a mission writes ----------------------------------------------------------------

    def fly(self) -> Wait[str]:
        """The flight up to (not including) the way home; returns the reason it is complete,
        or raises :meth:`end` with another status. Start it with :meth:`arm_and_take_off`."""
        raise NotImplementedError(f"{type(self).__name__} does not define fly()")

    def first_outputs(self) -> list[Output]:
        """What the mission outputs before the first observation (nothing by default)."""
        return []

    def go_home(self) -> Wait[None]:
        """Fly the way home before RTL, after a flight that did its work (by default none:
        the vehicle's RTL climbs to its return altitude and flies straight home)."""
        yield from ()

    def outcome_for(self, status: Status, reason: str) -> Outcome:
        """The outcome to report (a mission may add what it found)."""
        return Outcome(status, reason)

    @classmethod
    def envelope(cls, params: Any, intrinsics: Intrinsics) -> Envelope:  # noqa: ARG003
        """Where the mission will fly with these parameters and this camera (for the
        pre-flight fence check; unknown by default)."""
        return Envelope()

    # --- the outside: observations in, outputs out --------------------------------------------

    def start(self) -> list[Output]:
        """The outputs before the first observation (:meth:`first_outputs`)."""
        if self._started:
            raise MissionStateError("the mission was already started")
        self._started = True
        self._out.extend(self.first_outputs())
        next(self._gen)
        return self._take()

    def step(self, observation: Observation) -> list[Output]:
        """Feed one observation; returns what the mission does about it (may be empty)."""
        if not self._started:
            raise MissionStateError("call start() before step()")
        if self.outcome is not None:
            raise MissionStateError("the mission has ended")
        with contextlib.suppress(StopIteration):  # the flight's generator has finished
            self._gen.send(observation)
        return self._take()

    @property
    def done(self) -> bool:
        return self.outcome is not None

    @property
    def working(self) -> bool:
        """Whether :meth:`fly` still runs: the mission has not ended, nor begun its way
        home."""
        return self._in_fly

    def _take(self) -> list[Output]:
        out, self._out = self._out, []
        return out

    def emit(self, output: Output) -> None:
        """Add an output to those the current step returns (the scenario's steps use this)."""
        self._out.append(output)

    def event(self, level: Level, text: str) -> None:
        self.emit(Event(level, text))

    def _new_id(self) -> int:
        self._next_id += 1
        return self._next_id

    # --- the flight, and how it ends ----------------------------------------------------------

    def interrupt(self, status: Status, reason: str) -> list[Output]:
        """End :meth:`fly` now, from outside it, as if it had raised ``end(status, reason)``
        where it waits (a fleet calls a member off); the way home follows as after any end.
        Does nothing once ``fly`` has ended. Returns the outputs this makes."""
        if not self._in_fly:
            return []
        with contextlib.suppress(StopIteration):
            self._gen.throw(MissionEnd(status, reason))
        return self._take()

    def _run(self) -> Wait[None]:
        self._in_fly = True
        try:
            done = yield from self.fly()
            end = MissionEnd(Status.COMPLETED, done if isinstance(done, str) and done else "done")
        except MissionEnd as exc:
            end = exc
        self._in_fly = False
        self.event(
            Level.INFO if end.status is Status.COMPLETED else Level.WARNING,
            f"mission ends: {end.status.value}: {end.reason}",
        )
        try:
            yield from self._finish(end.status)
        except MissionEnd as exc:
            self.event(Level.ERROR, f"while finishing: {exc.reason}")
            # A crash is a crash whatever was achieved before; a flight that did its work but
            # could not come home and land is not 'completed' (nor 'partial', nor 'no-match').
            if exc.status is Status.CRASHED or end.status in _FLIES_HOME:
                end = MissionEnd(
                    exc.status, f"{exc.reason}, after '{end.status.value}: {end.reason}'"
                )
                self.event(Level.ERROR, f"mission ends: {end.status.value}: {end.reason}")
        self.outcome = self.outcome_for(end.status, end.reason)
        self.emit(self.outcome)

    def _finish(self, status: Status) -> Wait[None]:
        """Bring the vehicle home (or watch someone else do it) until it has landed.

        Until then a disarm in the air, or anywhere but on the ground at home, is a crash
        (raised as CRASHED). A vehicle still on the ground lands where it is: RTL would climb.
        A way home over the known roofs that cannot be flown leaves it to the vehicle's RTL,
        and then ends ABORTED with its reason; so does a vehicle that never lands.
        """
        if status in (Status.LINK_LOST, Status.CRASHED) or self.last is None:
            return
        landed = self._landed_and_disarmed
        way_home: MissionEnd | None = None
        if status is Status.TAKEOVER:
            self._airborne = False  # the pilot lands where they choose
            self._expected_modes = frozenset()
            self.event(Level.INFO, "no more commands; watching until the vehicle lands")
        elif self.last.landed and self.last.armed:
            self._airborne = False
            self.event(Level.INFO, "still on the ground: LAND to disarm (RTL would climb)")
            yield from self.set_mode("LAND")
        elif not landed(self.last):
            if status in self.go_home_after:
                try:
                    yield from self.go_home()
                except MissionEnd as exc:
                    if exc.status is not Status.ABORTED:
                        raise
                    self.event(Level.ERROR, f"the way home failed: {exc.reason}")
                    way_home = exc
            self.event(Level.INFO, "returning home (RTL)")
            self._landing = True
            yield from self.set_mode("RTL", also=("LAND",))
        ok = yield from self.wait_until(landed, self.flight.land_timeout_s)
        if not ok:
            if status in _FLIES_HOME:  # its work done, it did not come back: not a success
                raise MissionEnd(Status.ABORTED, "still flying when the mission stopped watching")
            self.event(Level.WARNING, "still flying when the mission stopped watching")
            return
        self.event(Level.INFO, "landed and disarmed")
        if way_home is not None:
            raise MissionEnd(Status.ABORTED, f"the way home: {way_home.reason}; landed by RTL")

    @staticmethod
    def _landed_and_disarmed(t: Telemetry) -> bool:
        return t.landed and not t.armed

    def _landed_at_home(self, t: Telemetry) -> bool:
        """A disarm that ends the landing the mission asked for: at home's height, not on a
        roof nor in the air. (Not by the landed flag: on a lossy link the vehicle's landed
        state can be older than the heartbeat that says it disarmed.)"""
        return self._landing and abs(t.pos_enu_m[2]) <= _HOME_HEIGHT_TOLERANCE_M

    # --- waiting: every observation passes through here ---------------------------------------

    def observe(self) -> Wait[Observation]:
        """The next observation, after the checks that apply everywhere."""
        while True:
            if self._deferred:
                obs = self._deferred.pop(0)
            else:
                obs = yield
            if isinstance(obs, LinkLost):
                yield from self._wait_for_link(obs)
                continue
            if isinstance(obs, LinkRestored):
                continue
            if isinstance(obs, Telemetry):
                self.last = obs
                if self._airborne and obs.pos_enu_m[2] > _HOME_HEIGHT_TOLERANCE_M:
                    self._left_ground = True
                if self._airborne and not obs.armed and not self._landed_at_home(obs):
                    if not self._left_ground and abs(obs.pos_enu_m[2]) <= _HOME_HEIGHT_TOLERANCE_M:
                        # e.g. PX4 disarming on the ground after a take-off it never flew
                        raise MissionEnd(
                            Status.ABORTED,
                            f"the vehicle disarmed on the ground at {obs.pos_enu_m[2]:.1f} m: "
                            "the take-off never left it",
                        )
                    raise MissionEnd(
                        Status.CRASHED,
                        f"the vehicle disarmed in the air at {obs.pos_enu_m[2]:.1f} m "
                        "(its crash check: it hit something)",
                    )
                self._check_mode(obs)
            return obs

    def _wait_for_link(self, lost: LinkLost) -> Wait[None]:
        self._link_was_lost = True
        self.event(
            Level.WARNING,
            f"link lost ({lost.silent_s:.1f} s of silence): waiting; the vehicle's failsafe "
            "is in charge",
        )
        while True:
            obs = yield
            if isinstance(obs, LinkRestored):
                self.event(Level.INFO, f"link restored after {obs.silent_s:.1f} s")
                return
            if isinstance(obs, LinkLost):
                if obs.silent_s > self.flight.link_lost_abort_s:
                    raise MissionEnd(Status.LINK_LOST, f"no link for {obs.silent_s:.0f} s")
                continue
            self._deferred.append(obs)  # e.g. a command result that arrived before the cut

    def _check_mode(self, t: Telemetry) -> None:
        # Down from the landing the mission asked for, the autopilot picks its own mode on the
        # ground (PX4 switches to Hold, at once or after a while disarmed): nobody took over.
        # Parked mid-mission (a fleet's leader waiting), likewise while it stays disarmed.
        touched_down = t.landed and (self._landing or (self._parked and not t.armed))
        if not self._expected_modes or t.mode in self._expected_modes or touched_down:
            self._link_was_lost = False  # the link came back and the vehicle kept its mode
            return
        who = "the vehicle's failsafe" if self._link_was_lost else "the pilot or a failsafe"
        status = Status.LINK_LOST if self._link_was_lost else Status.TAKEOVER
        raise MissionEnd(status, f"mode changed to {t.mode} by {who}")

    def now_ms(self) -> int:
        return self.last.time_boot_ms if self.last is not None else 0

    def wait_until(self, done: Callable[[Telemetry], bool], timeout_s: float) -> Wait[bool]:
        """Wait for telemetry that satisfies ``done``; False after ``timeout_s`` of vehicle time."""
        start_ms = self.now_ms()
        if self.last is not None and done(self.last):
            return True
        while True:
            obs = yield from self.observe()
            if isinstance(obs, Telemetry):
                if done(obs):
                    return True
                if obs.time_boot_ms - start_ms > timeout_s * 1000.0:
                    return False

    def pause(self, duration_s: float) -> Wait[None]:
        yield from self.wait_until(lambda _t: False, duration_s)

    # --- commands -----------------------------------------------------------------------------

    def command(
        self,
        make: Callable[[int], Command],
        what: str,
        *,
        retries: int = -1,
        done: Callable[[Telemetry], bool] | None = None,
    ) -> Wait[None]:
        """Issue a command until the vehicle accepts it, or the telemetry shows it ``done``
        (its ACK lost on the link); abort (RTL) after the retries, or at once when the vehicle
        refuses it for good (`CommandResult.final`)."""
        attempts = 1 + (self.flight.command_retries if retries < 0 else retries)
        detail = ""
        for attempt in range(1, attempts + 1):
            cmd = make(self._new_id())
            self.emit(cmd)
            result = yield from self._result(cmd.id)
            if result.accepted or (done is not None and self.last is not None and done(self.last)):
                return
            detail = result.detail
            if result.final:
                raise MissionEnd(Status.ABORTED, f"{what}: {detail}")
            self.event(Level.WARNING, f"{what}: {detail} (attempt {attempt} of {attempts})")
            if attempt < attempts:
                yield from self.pause(self.flight.retry_wait_s)
        raise MissionEnd(Status.ABORTED, f"{what} failed {attempts} times: {detail}")

    def _result(self, action_id: int) -> Wait[CommandResult]:
        while True:
            obs = yield from self.observe()
            if isinstance(obs, CommandResult) and obs.action_id == action_id:
                return obs

    def set_mode(self, mode: str, *, also: tuple[str, ...] = ()) -> Wait[None]:
        """Switch mode and wait until telemetry shows it; from then on any other mode (except
        ``also``) means someone else took over."""
        if self._expected_modes:  # the switch itself is not someone else's doing
            self._expected_modes = self._expected_modes | {mode, *also}
        yield from self.command(lambda i: SetMode(i, mode), f"mode {mode}")
        ok = yield from self.wait_until(lambda t: t.mode == mode, self.flight.move_slack_s)
        if not ok:
            raise MissionEnd(
                Status.ABORTED, f"the vehicle accepted mode {mode} but never showed it"
            )
        self._expected_modes = frozenset((mode, *also))

    def move(self, pos_enu_m: Vec3, heading_deg: float | None, what: str) -> Wait[None]:
        """Fly to a position (and heading) and wait until there and still."""
        p = self.flight
        for attempt in range(1, p.command_retries + 2):
            yield from self.command(lambda i: GoTo(i, pos_enu_m, heading_deg), what)
            timeout_s = _move_time_s(self.last, pos_enu_m, p) + p.move_slack_s
            arrived = yield from self.wait_until(
                lambda t: self._arrived(t, pos_enu_m, heading_deg), timeout_s
            )
            if arrived:
                return
            self.event(
                Level.WARNING, f"{what}: not reached in {timeout_s:.0f} s (attempt {attempt})"
            )
        raise MissionEnd(Status.ABORTED, f"{what}: position never reached")

    def _arrived(self, t: Telemetry, pos_enu_m: Vec3, heading_deg: float | None) -> bool:
        p = self.flight
        if _distance(t, pos_enu_m) > p.arrive_radius_m or t.speed_m_s > p.arrive_speed_m_s:
            return False
        return heading_deg is None or abs(wrap_180(t.heading_deg - heading_deg)) <= (
            p.heading_tolerance_deg
        )

    def photo(self, tag: str, pitch_deg: float) -> Wait[Photo]:
        """Point the gimbal (if needed), then take a photo and return it."""
        p = self.flight
        last = self.last
        if not p.gimbal:
            pass  # a camera fixed straight down: nothing to point
        elif last is None or abs(last.gimbal_pitch_deg - pitch_deg) > p.gimbal_tolerance_deg:
            yield from self.command(lambda i: SetGimbal(i, pitch_deg), f"gimbal to {pitch_deg:g}°")
            ok = yield from self.wait_until(
                lambda t: abs(t.gimbal_pitch_deg - pitch_deg) <= p.gimbal_tolerance_deg,
                p.move_slack_s,
            )
            if not ok:
                self.event(Level.WARNING, f"gimbal did not report {pitch_deg:g}°; photo anyway")
        cmd = TakePhoto(self._new_id(), tag)
        self.emit(cmd)
        while True:
            obs = yield from self.observe()
            if isinstance(obs, Photo) and obs.action_id == cmd.id:
                return obs
            if isinstance(obs, CommandResult) and obs.action_id == cmd.id and not obs.accepted:
                raise MissionEnd(Status.ABORTED, f"photo {tag!r}: {obs.detail}")

    def end(self, status: Status, reason: str) -> MissionEnd:
        """The exception that ends the flight (``raise mission.end(...)``)."""
        return MissionEnd(status, reason)

    def arm_and_take_off(self, alt_m: float) -> Wait[None]:
        """GUIDED, arm (retrying while pre-arm checks fail) and climb to ``alt_m``."""
        p = self.flight
        self.event(Level.INFO, "arming in GUIDED")
        self._parked = False
        yield from self.set_mode("GUIDED")
        start_ms = self.now_ms()
        refused = 0
        while True:
            cmd = Arm(self._new_id())
            self.emit(cmd)
            result = yield from self._result(cmd.id)
            if result.accepted:
                break
            if not refused:
                self.event(Level.WARNING, f"arming refused: {result.detail}; retrying")
            refused += 1
            if self.now_ms() - start_ms > p.arm_wait_s * 1000.0:
                raise MissionEnd(
                    Status.ABORTED, f"arming refused for {p.arm_wait_s:.0f} s: {result.detail}"
                )
            yield from self.pause(p.retry_wait_s)
        ok = yield from self.wait_until(lambda t: t.armed, p.move_slack_s)
        if not ok:
            raise MissionEnd(Status.ABORTED, "the vehicle accepted arming but never showed armed")
        self.event(Level.INFO, f"armed; taking off to {alt_m:g} m")
        # A take-off whose ACK was lost is flying: the vehicle refuses it again, and that is no
        # failure.
        yield from self.command(
            lambda i: Takeoff(i, alt_m), f"take-off to {alt_m:g} m", done=lambda t: not t.landed
        )
        self.airborne()
        climbed = yield from self.wait_until(
            lambda t: t.pos_enu_m[2] >= alt_m - p.arrive_radius_m,
            alt_m / p.climb_speed_m_s + p.move_slack_s,
        )
        if not climbed:
            raise MissionEnd(Status.ABORTED, f"take-off: {alt_m:g} m never reached")

    def land(self, what: str) -> Wait[None]:
        """LAND where it is and wait until it has landed and disarmed, mid-mission (a fleet's
        leader waits on the ground); :meth:`arm_and_take_off` flies it again. A disarm away
        from home's height is still a crash."""
        self.event(Level.INFO, f"landing: {what}")
        self._landing = True
        yield from self.set_mode("LAND")
        landed = yield from self.wait_until(self._landed_and_disarmed, self.flight.land_timeout_s)
        if not landed:
            raise MissionEnd(Status.ABORTED, f"landing ({what}): not landed in time")
        self._airborne = self._landing = self._left_ground = False
        self._parked = True
        self.event(Level.INFO, "landed and disarmed, waiting")

    def airborne(self, *, flying: bool = False) -> None:
        """From now until the return home, a vehicle that disarms has crashed; one that
        disarms on the ground before it was ever seen above home's height tolerance never took
        off (aborted). ``flying``: it is already in the air (taken over from a pilot)."""
        self._airborne = True
        self._left_ground = self._left_ground or flying


def _move_time_s(t: Telemetry | None, pos_enu_m: Vec3, p: FlightParams) -> float:
    """The longest a move should take: across at the slowest cruise speed, up or down at the
    slowest climb rate."""
    if t is None:
        return 0.0
    across_m = math.hypot(t.pos_enu_m[0] - pos_enu_m[0], t.pos_enu_m[1] - pos_enu_m[1])
    return across_m / p.cruise_speed_m_s + abs(t.pos_enu_m[2] - pos_enu_m[2]) / p.climb_speed_m_s


def _distance(t: Telemetry | None, pos_enu_m: Vec3) -> float:
    if t is None:
        return 0.0
    dx = t.pos_enu_m[0] - pos_enu_m[0]
    dy = t.pos_enu_m[1] - pos_enu_m[1]
    dz = t.pos_enu_m[2] - pos_enu_m[2]
    return math.sqrt(dx * dx + dy * dy + dz * dz)
