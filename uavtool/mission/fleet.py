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

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar, Self

from uavtool.checks import Range, check_fields
from uavtool.mission.airspace import EN, Airspace, Claim
from uavtool.mission.base import FlightMission, MissionInputs, Wait
from uavtool.mission.outputs import Level, Outcome, Status, Vec3


@dataclass(frozen=True, slots=True)
class FleetParams:
    """How a fleet keeps apart. Distances in metres."""

    separation_m: float = 5.0
    """No two vehicles of the fleet come closer than this (their positions)."""
    margin_m: float = 1.5
    """How far a vehicle may stray from the straight way it was sent along (tracking error in
    gusts, overshoot): every claim is widened by it."""
    claim_wait_s: float = 600.0
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

    @property
    def done(self) -> bool:
        return all(m.done for m in self.members)


class FleetMember(FlightMission):
    """One vehicle's part of a fleet mission. Subclass it as a one-vehicle mission (declare
    ``params_type`` with a :class:`FleetParams` group named by ``fleet_group``), write ``fly``
    with :meth:`take_off_to_layer` and :meth:`go` instead of ``arm_and_take_off`` and ``move``,
    and read or write :attr:`crew`. uavtool builds the members with :meth:`fleet`."""

    fleet_group: ClassVar[str] = "fleet"
    """The group of ``params_type`` that is the :class:`FleetParams`."""
    crew_type: ClassVar[type[Crew]] = Crew
    """The crew the members share (subclass :class:`Crew` to give it more)."""

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

    # --- where it is --------------------------------------------------------------------------

    @property
    def home_en_m(self) -> EN:
        """This vehicle's home in the fleet's frame."""
        return self.crew.homes_en_m[self.index]

    def to_fleet(self, pos: Vec3 | EN) -> EN:
        """A position of this vehicle's frame in the fleet's (east, north)."""
        hx, hy = self.home_en_m
        return (pos[0] + hx, pos[1] + hy)

    def from_fleet(self, en: EN) -> EN:
        hx, hy = self.home_en_m
        return (en[0] - hx, en[1] - hy)

    def base_layer_m(self) -> float:
        """The altitude of the lowest member's layer; a mission says which (default: the
        flight's RTL altitude of ArduCopter, 15 m)."""
        return 15.0

    def layer_m(self, index: int | None = None) -> float:
        """The altitude (above home) at which member ``index`` (default: this one) flies from
        place to place: the base layer, one layer step higher per member."""
        i = self.index if index is None else index
        return self.base_layer_m() + i * self.crew.fleet.layer_step_m

    # --- flying apart -------------------------------------------------------------------------

    def take_off_to_layer(self) -> Wait[None]:
        """Claim the column above home up to this member's layer, then take off to it."""
        layer = self.layer_m()
        home = self.to_fleet((0.0, 0.0))
        yield from self.claim(
            Claim.column(home, self.flight.arrive_radius_m, 0.0, layer, "take-off"), "take-off"
        )
        yield from self.arm_and_take_off(layer)
        self.crew.airspace.shrink(self.index, home, layer, "at its layer")

    def go(self, pos_enu_m: Vec3, heading_deg: float | None, what: str) -> Wait[None]:
        """Fly to a position (this vehicle's frame) inside claimed airspace: straight up or
        down in a column, across at this member's layer in a lane, or up to the layer,
        across, and down. Each part waits for its claim; arriving at the layer shrinks it."""
        last = self.last
        assert last is not None, "go() needs telemetry: take off first"
        here = last.pos_enu_m
        x, y, z = pos_enu_m
        tol = self.flight.arrive_radius_m
        layer = self.layer_m()
        if math.hypot(x - here[0], y - here[1]) <= tol:
            claim = Claim.column(self.to_fleet(here), tol, here[2], z, what)
        elif abs(here[2] - layer) <= tol and abs(z - layer) <= tol:
            claim = Claim.lane(self.to_fleet(here), self.to_fleet(pos_enu_m), layer, what)
        else:
            yield from self.go((here[0], here[1], layer), None, f"{what}: up to the layer")
            yield from self.go((x, y, layer), None, f"{what}: across")
            yield from self.go(pos_enu_m, heading_deg, what)
            return
        yield from self.claim(claim, what)
        yield from self.move(pos_enu_m, heading_deg, what)
        if abs(z - layer) <= tol:
            self.crew.airspace.shrink(self.index, self.to_fleet(pos_enu_m), z, what)

    def claim(self, claim: Claim, what: str) -> Wait[None]:
        """Wait (hovering where it is) until the airspace grants ``claim``; ABORTED after
        ``claim_wait_s``."""
        airspace = self.crew.airspace
        if airspace.request(self.index, claim):
            return
        other = airspace.blocker(self.index, claim)
        self.event(Level.INFO, f"{what}: waiting for vehicle {_sysid(other)} to clear the way")
        wait_s = self.crew.fleet.claim_wait_s
        granted = yield from self.wait_until(lambda _t: airspace.request(self.index, claim), wait_s)
        if not granted:
            other = airspace.blocker(self.index, claim)
            raise self.end(
                Status.ABORTED,
                f"{what}: vehicle {_sysid(other)} held the way for {wait_s:g} s",
            )

    def go_home(self) -> Wait[None]:
        """Back over home at this member's layer, then claim the column down for the landing
        (the vehicle's RTL then descends straight)."""
        if self.last is None or self.last.landed:
            return
        layer = self.layer_m()
        yield from self.go((0.0, 0.0, layer), None, "home")
        home = self.to_fleet((0.0, 0.0))
        yield from self.claim(
            Claim.column(home, self.flight.arrive_radius_m, 0.0, layer, "landing"), "landing"
        )

    def outcome_for(self, status: Status, reason: str) -> Outcome:
        if self.last is not None and self.last.landed and not self.last.armed:
            # Landed and disarmed: it holds only where it stands.
            self.crew.airspace.park(self.index, self.to_fleet(self.last.pos_enu_m))
        return super().outcome_for(status, reason)


def _sysid(index: int | None) -> str:
    return "?" if index is None else str(index + 1)
