"""Missions for fleets: one :class:`FleetMember` per vehicle, and the :class:`Crew` they share.

A fleet mission is written as a one-vehicle mission is — a :class:`FlightMission` subclass with
one ``fly`` generator — and every member is one instance of it, flying its own vehicle with
everything the base class does for one (commands and their retries, a crash at any moment, a
takeover, link loss, the way home). What makes them a fleet is the crew: the members read and
write it (who does what, what each has seen, who found what), and they fly only in airspace
the crew's :class:`~uavtool.mission.airspace.Airspace` granted them (:meth:`FleetMember.go`).

The runner feeds each member the observations of its own vehicle, all of them in one order (the
order the lockstep world produced them), so the crew — and every output — is a function of the
observations alone, as one vehicle's mission is: the rules of replay hold for the fleet.

Frames: each member flies in its own vehicle's frame (ENU metres around its own home), as a
one-vehicle mission does; the crew and its airspace use the fleet's frame, ENU metres around
the first vehicle's home (:attr:`FleetMember.home_en_m` is the difference).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar, Self

from uavtool.checks import Range, check_fields
from uavtool.mission.airspace import EN, Airspace, Claim
from uavtool.mission.base import FlightMission, MissionInputs, Wait
from uavtool.mission.observations import Observation, Photo, Telemetry
from uavtool.mission.outputs import GoTo, Level, Outcome, Output, Status, Vec3
from uavtool.nav.geometry import closest_on_segment


@dataclass(frozen=True, slots=True)
class FleetParams:
    """How a fleet keeps apart. Distances in metres."""

    separation_m: float = 5.0
    """No two vehicles of the fleet come closer than this (their positions)."""
    margin_m: float = 1.5
    """How far a vehicle may stray from the straight way it was sent along (tracking error in
    gusts, overshoot): every claim is widened by it."""
    claim_wait_s: float = 300.0
    """A member waits this long for airspace another holds, then aborts (RTL)."""

    RANGES: ClassVar[Any] = MappingProxyType(
        {
            "separation_m": Range(0.0, 1000.0, lo_open=True),
            "margin_m": Range(0.0, 100.0),
            "claim_wait_s": Range(0.0, 86_400.0, lo_open=True),
        }
    )

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="fleet")

    @property
    def layer_step_m(self) -> float:
        """How far apart two members' layers are: lanes flown at once on two layers then
        keep the separation with both margins."""
        return self.separation_m + 2.0 * self.margin_m


class Crew:
    """What the members of one fleet flight share: the airspace, the members themselves and a
    ``board`` of what they tell each other (any values; a member writes only plain data, so
    that a replay rebuilds the same board). ``homes_en_m[i]`` is vehicle ``i``'s home in the
    fleet's frame."""

    def __init__(
        self, params: Any, inputs: MissionInputs, homes_en_m: tuple[EN, ...], fleet: FleetParams
    ) -> None:
        self.params = params
        self.inputs = inputs
        self.homes_en_m = homes_en_m
        self.fleet = fleet
        self.airspace = Airspace(
            homes_en_m,
            separation_m=fleet.separation_m,
            margin_m=fleet.margin_m,
        )
        self.members: list[FleetMember] = []
        self.board: dict[str, Any] = {}

    @property
    def size(self) -> int:
        return len(self.homes_en_m)

    def call_off(self, index: int) -> str | None:  # noqa: ARG002 - for a crew that calls off
        """Why member ``index`` should stop its work now (its way home follows), or None: the
        runner asks before each observation. By default a member is never called off."""
        return None

    def outcome(self, outcomes: list[Outcome]) -> tuple[Status, str]:
        """The fleet's outcome from its members' (one each, in order): by default a crash if
        any crashed, else the worst of theirs (completed only when every member completed)."""
        worst = min(range(len(outcomes)), key=lambda i: WORST.index(outcomes[i].status))
        o = outcomes[worst]
        if o.status is Status.COMPLETED:
            return o.status, "every vehicle completed"
        return o.status, f"vehicle {worst + 1}: {o.reason}"


WORST = (
    Status.CRASHED,
    Status.LINK_LOST,
    Status.TAKEOVER,
    Status.ABORTED,
    Status.NO_MATCH,
    Status.PARTIAL,
    Status.COMPLETED,
)
"""Statuses from the worst outcome to the best."""
FAILED = frozenset({Status.CRASHED, Status.LINK_LOST, Status.TAKEOVER, Status.ABORTED})
"""Statuses of a flight that failed, whatever its mission achieved."""


class FleetMember(FlightMission):
    """One vehicle's part of a fleet mission. Subclass it as a one-vehicle mission (declare
    ``params_type`` with a :class:`FleetParams` group named by ``fleet_group``), write ``fly``
    with :meth:`take_off` instead of ``arm_and_take_off``, and read or write :attr:`crew`.
    uavtool builds the members with :meth:`fleet`.

    A member lives in the fleet's frame: the telemetry and photos it is given, and the moves it
    makes, are in ENU metres around the first vehicle's home (its own home is
    :attr:`home_en_m`); the runner's vehicle still gets its position targets in its own frame.
    Every :meth:`move` claims its airspace first (:class:`~uavtool.mission.airspace.Airspace`)
    and waits, hovering, until the others leave it clear."""

    fleet_group: ClassVar[str] = "fleet"
    """The group of ``params_type`` that is the :class:`FleetParams`."""
    crew_type: ClassVar[type[Crew]] = Crew
    """The crew the members share (subclass :class:`Crew` to give it more)."""
    go_home_after: ClassVar[frozenset[Status]] = frozenset(
        {Status.COMPLETED, Status.PARTIAL, Status.NO_MATCH, Status.ABORTED}
    )

    crew: Crew
    index: int
    """This member's vehicle: 0 for the first."""

    @classmethod
    def fleet(cls, params: Any, inputs: MissionInputs, homes_en_m: tuple[EN, ...]) -> list[Self]:
        """The members of one flight, one per home (fleet frame), sharing one crew."""
        crew = cls.crew_type(params, inputs, homes_en_m, getattr(params, cls.fleet_group))
        members = [cls(params, inputs) for _ in homes_en_m]
        for i, member in enumerate(members):
            member.crew, member.index = crew, i
        crew.members = list(members)
        return members

    # --- the fleet's frame --------------------------------------------------------------------

    @property
    def home_en_m(self) -> EN:
        """This vehicle's home in the fleet's frame."""
        return self.crew.homes_en_m[self.index]

    def start(self) -> list[Output]:
        return self._to_vehicle(super().start())

    def step(self, observation: Observation) -> list[Output]:
        out: list[Output] = []
        reason = self.crew.call_off(self.index)
        if reason is not None:
            out = self.interrupt(Status.COMPLETED, f"called off: {reason}")
        if not self.done:
            out += super().step(self._to_fleet(observation))
        return self._to_vehicle(out)

    def _to_fleet(self, obs: Observation) -> Observation:
        hx, hy = self.home_en_m
        if isinstance(obs, Telemetry):
            x, y, z = obs.pos_enu_m
            return dataclasses.replace(obs, pos_enu_m=(x + hx, y + hy, z))
        if isinstance(obs, Photo):
            x, y, z = obs.pose.pos_enu_m
            pose = dataclasses.replace(obs.pose, pos_enu_m=(x + hx, y + hy, z))
            return dataclasses.replace(obs, pose=pose)
        return obs

    def _to_vehicle(self, outputs: list[Output]) -> list[Output]:
        hx, hy = self.home_en_m
        if hx == hy == 0.0:
            return outputs
        return [
            dataclasses.replace(
                o, pos_enu_m=(o.pos_enu_m[0] - hx, o.pos_enu_m[1] - hy, o.pos_enu_m[2])
            )
            if isinstance(o, GoTo)
            else o
            for o in outputs
        ]

    # --- layers -------------------------------------------------------------------------------

    def base_layer_m(self) -> float:
        """The altitude of the first member's layer; a mission says which (default: 15 m,
        ArduCopter's RTL altitude)."""
        return 15.0

    def layer_m(self, index: int | None = None) -> float:
        """The altitude (above home) at which member ``index`` (default: this one) flies from
        place to place: the base layer, one layer step higher per member. Lanes on two layers
        never meet: members fly across at once."""
        i = self.index if index is None else index
        return self.base_layer_m() + i * self.crew.fleet.layer_step_m

    # --- flying apart -------------------------------------------------------------------------

    def take_off(self, alt_m: float) -> Wait[None]:
        """Claim the column above where it stands up to ``alt_m``, then take off to it."""
        last = self.last
        at = (last.pos_enu_m[0], last.pos_enu_m[1]) if last is not None else self.home_en_m
        column = Claim.column(at, self.flight.arrive_radius_m, 0.0, alt_m, "take-off")
        yield from self.claim(column, "take-off")
        yield from self.arm_and_take_off(alt_m)
        self.crew.airspace.shrink(self.index, at, alt_m, "took off")

    def land_at_home(self, what: str) -> Wait[None]:
        """Back over home at this member's layer (the column down claimed), land, and hold
        only where it stands."""
        yield from self.go_home()
        yield from self.land(what)
        last = self.last
        assert last is not None
        self.crew.airspace.park(self.index, (last.pos_enu_m[0], last.pos_enu_m[1]))

    def move(self, pos_enu_m: Vec3, heading_deg: float | None, what: str) -> Wait[None]:
        """A move inside claimed airspace. At or above this member's layer: the straight way
        there, claimed, flown, then only the point arrived at held. Below it: the way's
        airspace from the layer down to the lowest point of the way, held until the member is
        back at its layer (a move inside it needs no other claim). The way is drawn from
        where the vehicle is when it is granted, not when it was first asked for: a vehicle
        called off mid-move flies on to its last target while it waits."""
        last = self.last
        assert last is not None, "move() needs telemetry: take off first"
        layer = self.layer_m()
        if last.landed and not last.armed:  # it landed to wait (land()): up first
            yield from self.take_off(layer)
        x, y, z = pos_enu_m
        tol = self.flight.arrive_radius_m
        airspace = self.crew.airspace
        below = z < layer - tol

        def way() -> Claim | None:
            """The airspace from here to there; None when what it holds covers both."""
            assert self.last is not None
            here = self.last.pos_enu_m
            at = (here[0], here[1])
            if here[2] >= layer - tol and not below:
                return Claim(at, (x, y), tol, min(here[2], z), max(here[2], z), what)
            held = airspace.held[self.index]
            if held.covers(at, here[2], 0.0) and held.covers((x, y), z, 0.0):
                return None
            return Claim(at, (x, y), tol, min(here[2], z), max(layer, here[2], z), what)

        here = last.pos_enu_m
        if (
            math.hypot(here[0] - x, here[1] - y) > tol
            and abs(here[2] - z) > tol
            and not airspace.request(self.index, way() or airspace.held[self.index])
        ):
            # The straight way, up or down across, is held: the higher way in two legs (up,
            # then across; or across, then down), nowhere lower than the straight one.
            first = (here[0], here[1], z) if z > here[2] else (x, y, here[2])
            yield from self.move(first, heading_deg, what)
            yield from self.move(pos_enu_m, heading_deg, what)
            return
        if abs(here[2] - z) <= tol and not below:
            wanted = way()
            if wanted is not None and not airspace.request(self.index, wanted):
                via = self._around(wanted)
                if via is not None:
                    # Across, held where a vehicle hovers or lands: around it, where the
                    # mission says the way is clear, instead of waiting.
                    wx, wy, holder = via
                    around = f"{what}: around vehicle {holder}"
                    self.event(Level.INFO, f"{around}, by ({wx:.1f}, {wy:.1f})")
                    yield from self.move((wx, wy, z), None, around)
                    yield from self.move(pos_enu_m, heading_deg, what)
                    return
        if (yield from self.claim(way, what, give_way=True)):
            # It climbed out of the way of a vehicle that waited for it: from there again.
            yield from self.move(pos_enu_m, heading_deg, what)
            return
        yield from super().move(pos_enu_m, heading_deg, what)
        if not below:
            airspace.shrink(self.index, (x, y), z, what)
        else:  # only the way back up to its layer is still needed
            airspace.narrow(self.index, Claim.column((x, y), tol, z, max(layer, z), what))

    def claim(
        self,
        claim: Claim | Callable[[], Claim | None],
        what: str,
        *,
        give_way: bool = False,
    ) -> Wait[bool]:
        """Wait (hovering where it is, or flying on to its last target) until the airspace
        grants ``claim`` (or the claim ``claim()`` makes each time it asks, from where the
        vehicle then is; None: nothing to ask for); ABORTED after ``claim_wait_s``. With
        ``give_way``, when the vehicle holding it up waits in turn for this one and goes
        first (the lower index), this one climbs out of its way instead (:meth:`give_way`)
        and True says the claim was not granted: the caller asks again from there."""
        airspace = self.crew.airspace
        make = claim if callable(claim) else lambda: claim
        got = False

        def granted(_t: Telemetry | None = None) -> bool:
            nonlocal got
            wanted = make()
            got = wanted is None or airspace.request(self.index, wanted)
            return got

        def deadlock() -> int | None:
            """A vehicle with a lower index that waits for this one while this one waits
            for it."""
            return next(
                (
                    o
                    for o in range(self.index)
                    if airspace.waits_for(self.index, o) and airspace.waits_for(o, self.index)
                ),
                None,
            )

        if granted():
            return False
        self.event(
            Level.INFO, f"{what}: waiting for vehicle {self._blocker(make)} to clear the way"
        )
        wait_s = self.crew.fleet.claim_wait_s
        t0 = self.now_ms()
        yielding = [give_way]  # until it tried once and could not

        def settled(t: Telemetry) -> bool:
            return granted(t) or (yielding[0] and deadlock() is not None)

        while True:
            left_s = wait_s - (self.now_ms() - t0) / 1000.0
            yield from self.wait_until(settled, max(left_s, 0.0))
            if got:
                return False
            other = deadlock() if yielding[0] else None
            if other is not None and (yield from self.give_way(other)):
                return True
            if self.now_ms() - t0 >= wait_s * 1000.0:
                raise self.end(
                    Status.ABORTED,
                    f"{what}: vehicle {self._blocker(make)} held the way for {wait_s:g} s",
                )
            if other is not None:  # it could not climb: no more giving way
                yielding[0] = False

    def wait_giving_way(self, until: Callable[[], bool], timeout_s: float) -> Wait[bool]:
        """Wait, hovering, until ``until()`` (False after ``timeout_s``); a vehicle that waits
        meanwhile for airspace this one holds is let through: this one climbs out of its way
        (:meth:`give_way`), each time it can."""
        airspace = self.crew.airspace
        t0 = self.now_ms()
        can = [True]

        def settled(_t: Telemetry) -> bool:
            return until() or (can[0] and airspace.holding_up(self.index) is not None)

        while not until():
            left_s = timeout_s - (self.now_ms() - t0) / 1000.0
            if left_s <= 0.0:
                return False
            yield from self.wait_until(settled, left_s)
            other = airspace.holding_up(self.index)
            if not until() and other is not None and can[0]:
                can[0] = yield from self.give_way(other)
        return True

    def give_way(self, other: int) -> Wait[bool]:
        """Out of the way of vehicle ``other``'s wanted claim by the separation (with both
        margins): straight up over it where it is, or else aside, across at its altitude,
        where the mission says the way is clear (:meth:`clear_aside`). False, without
        moving, when it stands on the ground, ``other`` wants nothing, or neither way is
        granted."""
        last = self.last
        airspace = self.crew.airspace
        wanted = airspace.wanted.get(other)
        if last is None or last.landed or wanted is None:
            return False
        x, y, z = last.pos_enu_m
        tol = self.flight.arrive_radius_m
        gap = airspace.needed_m(Claim.point((x, y), z), wanted) + tol
        what = f"giving way to vehicle {other + 1}"
        top = wanted.high_m + gap
        up = Claim.column((x, y), tol, z, top, what)
        if top > z and airspace.request(self.index, up):
            self.event(Level.INFO, f"{what}: up to {top:.1f} m")
            yield from FlightMission.move(self, (x, y, top), None, what)
            airspace.shrink(self.index, (x, y), top, what)
            return True
        aside = _aside((x, y), wanted, wanted.radius_m + gap, self.home_en_m)
        lane = Claim((x, y), aside, tol, z, z, what)
        if not self.clear_aside((x, y), aside, z) or not airspace.request(self.index, lane):
            return False
        self.event(Level.INFO, f"{what}: aside to ({aside[0]:.1f}, {aside[1]:.1f})")
        yield from FlightMission.move(self, (*aside, z), None, what)
        airspace.shrink(self.index, aside, z, what)
        return True

    def _around(self, lane: Claim) -> tuple[float, float, int] | None:
        """A point to fly ``lane`` (across, at one altitude) around the vehicle whose point or
        column holds it, both legs apart from every other claim and clear of what the
        mission knows stands there (:meth:`clear_aside`); and which vehicle. None when the
        holder flies a way of its own (it moves on) or no such point is found: beyond the
        lane's end straight away from the holder, or beside the holder, either side."""
        airspace = self.crew.airspace
        other = airspace.blocker(self.index, lane)
        if other is None:
            return None
        held = airspace.held[other]
        if held.a != held.b:
            return None
        tol = self.flight.arrive_radius_m
        z = lane.low_m
        gap = 1.2 * (airspace.needed_m(lane, held) + held.radius_m + tol)
        (ax, ay), (bx, by), (cx, cy) = lane.a, lane.b, held.a
        candidates = []
        d = math.hypot(bx - cx, by - cy)
        if d > 1e-6:
            candidates.append((bx + (bx - cx) / d * gap, by + (by - cy) / d * gap))
        length = math.hypot(bx - ax, by - ay)
        if length > 1e-6:
            nx, ny = -(by - ay) / length, (bx - ax) / length
            candidates += [(cx + nx * gap, cy + ny * gap), (cx - nx * gap, cy - ny * gap)]
        for w in candidates:
            legs = (Claim(lane.a, w, tol, z, z), Claim(w, lane.b, tol, z, z))
            if all(airspace.blocker(self.index, leg) is None for leg in legs) and all(
                self.clear_aside(leg.a, leg.b, z) for leg in legs
            ):
                return (w[0], w[1], other + 1)
        return None

    def clear_aside(self, a: EN, b: EN, alt_m: float) -> bool:  # noqa: ARG002
        """Whether the straight way from ``a`` to ``b`` at ``alt_m`` is clear of everything
        the mission knows stands there (a mission that knows its world says; by default
        no member moves aside, only up)."""
        return False

    def _blocker(self, make: Callable[[], Claim | None]) -> str:
        wanted = make()
        other = None if wanted is None else self.crew.airspace.blocker(self.index, wanted)
        return _sysid(other)

    def go_home(self) -> Wait[None]:
        """Back over home at this member's layer, then claim the column down for the landing
        (the vehicle's RTL then descends straight)."""
        if self.last is None or self.last.landed:
            return
        layer = max(self.layer_m(), self.last.pos_enu_m[2])
        home = self.home_en_m
        yield from self.move((home[0], home[1], layer), None, "home")
        column = Claim.column(home, self.flight.arrive_radius_m, 0.0, layer, "landing")
        yield from self.claim(column, "landing")

    def outcome_for(self, status: Status, reason: str) -> Outcome:
        if self.last is not None and self.last.landed and not self.last.armed:
            # Landed and disarmed: it holds only where it stands.
            self.crew.airspace.park(self.index, self.last.pos_enu_m[:2])
        return super().outcome_for(status, reason)


def _aside(at: EN, claim: Claim, distance_m: float, home: EN) -> EN:
    """The point ``distance_m`` from ``claim``'s segment, straight away from it through
    ``at`` (towards ``home`` when ``at`` lies on it)."""
    px, py = closest_on_segment(at, claim.a, claim.b)
    ux, uy = at[0] - px, at[1] - py
    norm = math.hypot(ux, uy)
    if norm < 1e-6:
        ux, uy = home[0] - px, home[1] - py
        norm = math.hypot(ux, uy)
        if norm < 1e-6:
            ux, uy, norm = 1.0, 0.0, 1.0
    return (px + ux / norm * distance_m, py + uy / norm * distance_m)


def _sysid(index: int | None) -> str:
    return "?" if index is None else str(index + 1)
