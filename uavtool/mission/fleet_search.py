"""The search mission flown by a fleet: one search, several pairs of eyes.

The first vehicle (the leader) flies the search as one vehicle does — the overview, the
points of interest, every decision — but it does not look at every point of interest itself:
as soon as the overview is measured it shares what it knows (the points of interest, the roofs
measured and those of unknown height, the ground it saw, the transit altitude); each helper
then takes the next point of its visiting order that no one has. A helper flies to its point,
looks at it as the leader would (:func:`~uavtool.mission.search.inspect`: the same looks,
closer looks and looks again) and gives the leader its looks. The leader judges every point in
the visiting order, from the helpers' looks (its own when no helper is left), with the
search's own logic: the same match, rivals and refusals. Once it has decided, the helper at
the target photographs it from above and plans the side photos; the helper still flying nearest
to the target takes one side photo meanwhile (:meth:`FleetSearchMission.side_elsewhere`), the
modeller the other, and builds the model; the other helpers are called off (they fly home and
land), and the leader lands once the side photos are handed out (once the one handed over is
in, when its landing would hold either vehicle's way to its side photo).

Each member crosses at a transit altitude of its own (the leader's, one layer step higher per
helper) and claims every move's airspace (:class:`~uavtool.mission.fleet.FleetMember`), so the
vehicles never come closer than ``fleet.separation_m``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

from uavtool.mission.airspace import Claim
from uavtool.mission.analysis import roof_between
from uavtool.mission.fleet import FAILED, WORST, Crew, FleetMember, FleetParams
from uavtool.mission.looks import Found, Look
from uavtool.mission.mission import SearchMission
from uavtool.mission.modelling import photograph_and_model
from uavtool.mission.outputs import Level, Outcome, Status
from uavtool.mission.params import Params
from uavtool.mission.search import (
    Inspection,
    Inspector,
    inspect,
    measure_from_another_altitude,
)
from uavtool.mission.sides import HandedSide, side_view
from uavtool.nav.geometry import point_segment_distance

if TYPE_CHECKING:
    from collections.abc import Callable

    from uavtool.mission.base import Wait
    from uavtool.mission.outputs import PointOfInterest
    from uavtool.mission.sides import SidePlan
    from uavtool.mission.survey import Survey
    from uavtool.nav import Viewpoint
    from uavtool.vision import Shape
    from uavtool.vision.model3d import View


STANDBY_M = 10.0
"""How high a helper waits over its home for the leader's survey."""


@dataclass(frozen=True, slots=True)
class FleetSearchParams(Params):
    """The search's parameters and the fleet's."""

    fleet: FleetParams = field(default_factory=FleetParams)


@dataclass(slots=True)
class _Shared:
    """What the leader shares once the overview is measured."""

    seen: Survey
    transit_m: float
    ceiling_m: float | None
    seen_ground: Any
    peeks: list[Any]
    from_above: list[Any]
    unknown: dict[int, Any]
    roofs: tuple[Any, ...]
    overview: Any


class SearchCrew(Crew):
    """The board of a fleet's search: what the leader shared, who looks at which point of
    interest, the looks given back, and whether the search has decided."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.shared: _Shared | None = None
        self.tasks: dict[int, int] = {}
        """Helper → the point of interest it is looking at for the leader."""
        self.results: dict[int, Inspection] = {}
        """Point of interest → the looks a helper took of it, not yet judged."""
        self.taken: set[int] = set()
        """Points of interest handed out, or looked at by the leader."""
        self.decided = False
        self.todo: list[int] = []
        """The leader's points of interest still to judge, in its visiting order."""
        self.looked_by: dict[int, int] = {}
        """Point of interest → the helper that looked at it."""
        self.modeller: int | None = None
        """The helper that photographs the target and builds the model (it is there)."""
        self.model_job: tuple[Found, Survey] | None = None
        self.measured: dict[int, float | None] = {}
        """Point of interest → the roof height its helper measured after a match."""
        self.model_done = False
        """The modeller has photographed the target and tried to build the model."""
        self.side_helper: int | None = None
        """The helper that takes one side photo for the modeller, at once (the nearest to
        the target of those still flying)."""
        self.side_job: tuple[SidePlan, Viewpoint, tuple[int, int, int]] | None = None
        """The side photo the modeller hands over: its plan, viewpoint and the roof's colour."""
        self.side_result: tuple[View, Viewpoint] | None = None
        self.side_done = False
        """The side helper has taken its photo, or failed to."""
        self.side_ways: list[tuple[tuple[float, float], tuple[float, float]]] = []
        """Where the modeller and the side helper fly for the side photos, from where each is
        when the photo is handed over (fleet frame, metres)."""

    def next_task(self, helper: int) -> int | None:
        """The first point of interest still to judge that no one has, now ``helper``'s."""
        for k in self.todo:
            if k not in self.taken:
                self.taken.add(k)
                self.tasks[helper] = k
                return k
        return None

    def call_off(self, index: int) -> str | None:
        if index > 0 and self.decided and index not in (self.modeller, self.side_helper):
            return "the first vehicle's search has decided"
        return None

    def outcome(self, outcomes: list[Outcome]) -> tuple[Status, str]:
        """The leader's (it judged, and says whether the model was built), unless a member's
        flight failed: a crash, a lost link, a takeover or an abort anywhere is the fleet's,
        the worst first, with what the search found beside it."""
        failed = [i for i, o in enumerate(outcomes) if o.status in FAILED]
        lead = outcomes[0]
        if not failed:
            return lead.status, lead.reason
        worst = min(failed, key=lambda i: WORST.index(outcomes[i].status))
        o = outcomes[worst]
        found = "" if worst == 0 else f"; the search: {lead.status.value}: {lead.reason}"
        return o.status, f"vehicle {worst + 1}: {o.reason}{found}"


class FleetSearchMission(FleetMember, SearchMission):
    """Find the target with several vehicles, photograph it from three sides, model it."""

    name: ClassVar[str] = "fleet-search"
    params_type: ClassVar[type[Any]] = FleetSearchParams
    crew_type: ClassVar[type[Crew]] = SearchCrew
    flight_group: ClassVar[str] = "mission"

    crew: SearchCrew

    def __init__(self, params: FleetSearchParams, inputs: Any) -> None:
        super().__init__(params, inputs)
        self.inspected = 0
        self.candidates = 0
        """How many of its looks matched the target."""

    def base_layer_m(self) -> float:
        shared = self.crew.shared
        return shared.transit_m if shared is not None else self.params.mission.overview_alt_m

    def layer_m(self, index: int | None = None) -> float:
        """The leader crosses on the top layer, helper ``h`` on layer ``h - 1`` from the
        bottom: a leader waiting for a helper's looks, on its layer, is in no helper's way
        down to a point of interest."""
        i = self.index if index is None else index
        n = self.crew.size
        step = self.crew.fleet.layer_step_m
        return self.base_layer_m() + ((n - 1) if i == 0 else (i - 1)) * step

    def above(self, altitude_m: float) -> float:
        return altitude_m + self.layer_m() - self.base_layer_m()

    # --- the leader ---------------------------------------------------------------------------

    def fly(self) -> Wait[str]:
        if self.index > 0:
            return (yield from self._help())
        try:
            return (yield from super().fly())
        finally:
            self.crew.decided = True  # whatever ended the search, the helpers go home

    def take_off_to(self, alt_m: float) -> Wait[None]:
        yield from self.take_off(alt_m)

    def inspector(self, seen: Survey, transit_m: float) -> Inspector | None:
        crew = self.crew
        crew.shared = _Shared(
            seen,
            transit_m,
            self.ceiling_m,
            self.seen_ground,
            self.peeks,
            self.from_above,
            self.unknown,
            self.roofs,
            self.overview,
        )
        if crew.size == 1:
            return None

        def look_at(k: int, todo: list[int]) -> Wait[Inspection]:
            crew.todo = [k, *todo]  # the helpers take them in this order
            if self._helpers_flying():
                # a helper has it, or will take it: wait above every helper's way
                yield from self._wait_above()
                yield from self.wait_until(
                    lambda _t: self._answered(k), self.flight.land_timeout_s * 10
                )
            if k in crew.results:
                self.visited.append(k)
                return crew.results.pop(k)
            self.event(Level.INFO, f"point of interest {k}: no helper left: looking at it")
            crew.taken.add(k)
            return (yield from inspect(self, k, seen.pois, seen.photo, seen.shapes, transit_m))

        return look_at

    def searched(self, found: Found | None) -> None:
        crew = self.crew
        if found is not None:
            helper = crew.looked_by.get(found.poi.index)
            if helper is not None and not crew.members[helper].done:
                crew.modeller = helper
                crew.side_helper = self._side_helper(found)
        crew.decided = True

    def _side_helper(self, found: Found) -> int | None:
        """The helper, still flying, nearest to the target that is not the modeller: it takes
        one side photo while the modeller takes the other."""
        crew = self.crew
        x, y = found.poi.pos_en_m
        free = [
            i for i, member in enumerate(crew.members) if 0 < i != crew.modeller and member.working
        ]
        return min(free, key=lambda i: (_distance(crew.members[i], x, y), i), default=None)

    def side_elsewhere(
        self,
        plan: SidePlan,
        viewpoints: tuple[Viewpoint, ...],
        colour_rgb: tuple[int, int, int],
    ) -> HandedSide | None:
        crew = self.crew
        h = crew.side_helper
        if h is None or h == self.index or not crew.members[h].working or len(viewpoints) < 2:
            return None
        helper = crew.members[h]
        # the helper takes the viewpoint nearer to it; this vehicle, over the target, the other
        vp = min(viewpoints, key=lambda v: _distance(helper, v.pos_enu_m[0], v.pos_enu_m[1]))
        # Its own copy of the plan: it crosses on its own layer and learns on its own way.
        crew.side_job = (
            dataclasses.replace(
                plan,
                obstacles=list(plan.obstacles),
                cautious=list(plan.cautious),
                unknown=list(plan.unknown),
                heights=list(plan.heights),
            ),
            vp,
            colour_rgb,
        )
        self.event(Level.INFO, f"vehicle {h + 1} takes the {vp.name} photo meanwhile")
        own = next(v for v in viewpoints if v is not vp)
        crew.side_ways = [
            (_where(member), (v.pos_enu_m[0], v.pos_enu_m[1]))
            for member, v in ((self, own), (helper, vp))
        ]

        def collect() -> Wait[tuple[View, Viewpoint] | None]:
            yield from self.wait_until(
                lambda _t: crew.side_done or helper.done, self.flight.land_timeout_s * 10
            )
            got = crew.side_result
            if got is not None and crew.side_job is not None and crew.side_job[0].grown:
                # its photo showed the building taller: planned for that from now on
                plan.taller(self, crew.side_job[0].params.assumed_height_m)
            return got

        return HandedSide(vp.name, collect)

    def standing_vehicles(self) -> list[tuple[tuple[tuple[float, float], ...], float]]:
        """The other members' homes, where each stands before it flies and lands when it is
        done: around each, a square as high as the separation and this member's margin (a
        parked vehicle keeps none) and that much wider than a claim, so the model's photos
        are planned again where the airspace would never grant a viewpoint."""
        fleet = self.crew.fleet
        high = fleet.separation_m + fleet.margin_m  # a parked vehicle keeps no margin
        r = high + self.flight.arrive_radius_m  # a claim's own width
        return [
            (((e - r, n - r), (e + r, n - r), (e + r, n + r), (e - r, n + r)), high)
            for i, (e, n) in enumerate(self.crew.homes_en_m)
            if i != self.index
        ]

    def model_target(self, found: Found, seen: Survey, transit_m: float) -> Wait[None]:
        crew = self.crew
        h = crew.modeller
        if h is None or crew.members[h].done:
            yield from super().model_target(found, seen, transit_m)
            return
        self.event(Level.INFO, f"vehicle {h + 1}, at the target, photographs it and models it")
        crew.model_job = (found, seen)
        helper = crew.members[h]
        s = crew.side_helper
        if s is not None:
            # Up above every layer until the side photos are handed out; and until the one
            # handed over is in, if its landing's column would hold the way of either vehicle
            # to its side photo.
            side = crew.members[s]
            yield from self.wait_until(
                lambda _t: crew.side_job is not None or crew.side_done or side.done,
                self.flight.land_timeout_s * 10,
            )
            if self._landing_in_the_way():
                self.event(
                    Level.INFO, f"waiting for vehicle {s + 1}'s side photo: home is on the way"
                )
                yield from self.wait_until(
                    lambda _t: crew.side_done or side.done, self.flight.land_timeout_s * 10
                )
        # Home meanwhile: the leader's part in the air is done.
        yield from self.land_at_home(f"vehicle {h + 1} builds the model")
        yield from self.wait_until(
            lambda _t: crew.model_done or helper.done, self.flight.land_timeout_s * 10
        )
        assert isinstance(helper, SearchMission)
        self.model_built, self.model = helper.model_built, helper.model
        self.viewpoints, self.no_model = helper.viewpoints, helper.no_model
        if self.model_built:
            self.event(Level.INFO, f"vehicle {h + 1} built the model")

    def _landing_in_the_way(self) -> bool:
        """Whether the column this member lands in would come nearer a way to a side photo
        still to be taken than two claims may (the separation, both margins and both
        widths)."""
        crew = self.crew
        if crew.side_done:
            return False
        near_m = crew.fleet.layer_step_m + 2.0 * self.flight.arrive_radius_m
        home = self.home_en_m
        return any(point_segment_distance(home, a, b) < near_m for a, b in crew.side_ways)

    def measure_roof(
        self, k: int, poi: PointOfInterest, look: Look, shape: Shape
    ) -> Wait[float | None]:
        crew = self.crew
        helper = crew.looked_by.get(k)
        if self.index == 0 and helper is not None:
            yield from self.wait_until(
                lambda _t: k in crew.measured or crew.members[helper].done,
                self.flight.land_timeout_s * 10,
            )
            if k in crew.measured:
                return crew.measured[k]
        return (yield from super().measure_roof(k, poi, look, shape))

    def _answered(self, k: int) -> bool:
        """Whether point of interest ``k``'s looks are in, or no helper will bring them (the
        one that took it ended, or none is left to take it): then the leader looks itself."""
        crew = self.crew
        if k in crew.results:
            return True
        owner = next((h for h, t in crew.tasks.items() if t == k), None)
        if owner is not None:
            return crew.members[owner].done
        return not self._helpers_flying()

    def _helpers_flying(self) -> bool:
        """Whether a helper may still look at something."""
        return any(not m.done for m in self.crew.members[1:])

    def _wait_above(self) -> Wait[None]:
        """Up to where the leader waits for its helpers' looks, once."""
        last = self.last
        top = self._waiting_m()
        if last is not None and last.pos_enu_m[2] < top - self.flight.arrive_radius_m:
            x, y, _ = last.pos_enu_m
            yield from self.move((x, y, top), None, f"waiting for the helpers at {top:.1f} m")

    def _waiting_m(self) -> float:
        """Where the leader waits for a helper's looks: a layer step above the highest any
        helper crosses at (the ceiling, on the highest helper's layer)."""
        shared = self.crew.shared
        assert shared is not None
        highest = max(shared.transit_m, shared.ceiling_m or 0.0)
        return highest + (self.crew.size - 1) * self.crew.fleet.layer_step_m

    def learn_roof(
        self, index: int, footprint: tuple[tuple[float, float], ...], roof_m: float
    ) -> None:
        """A roof measured by any member is known to all."""
        for member in self.crew.members:
            if isinstance(member, SearchMission):
                SearchMission.learn_roof(member, index, footprint, roof_m)

    # --- a helper -----------------------------------------------------------------------------

    def _help(self) -> Wait[str]:
        crew = self.crew
        # Up while the leader surveys, to wait over home: ready when the first look is due.
        yield from self.take_off(self._standby_m())
        waited = yield from self.wait_until(
            lambda _t: crew.shared is not None or crew.decided, self.flight.land_timeout_s * 10
        )
        shared = crew.shared
        if not waited or shared is None or self._called_off():
            return "the search decided before it needed this vehicle"
        self.transit_m = self.layer_m()
        self.ceiling_m, self.seen_ground = shared.ceiling_m, shared.seen_ground
        self.peeks, self.unknown, self.roofs = shared.peeks, shared.unknown, shared.roofs
        self.from_above = shared.from_above
        self.overview = shared.overview
        self.plan = None
        seen = shared.seen
        layer = self.transit_m
        yield from self.move((*self.home_en_m, layer), None, f"up to its layer, {layer:.1f} m")
        while not self._called_off():
            k = crew.next_task(self.index)
            if k is None:
                break  # nothing left to look at: home (the leader's list only ever shrinks)
            self.event(Level.INFO, f"point of interest {k}: looking at it for vehicle 1")
            looks, upper = yield from inspect(self, k, seen.pois, seen.photo, seen.shapes, layer)
            crew.results[k] = (looks, upper)
            crew.looked_by[k] = self.index
            del crew.tasks[self.index]
            self.inspected += 1
            look = looks[-1]
            if look.judgement.matched:
                self.candidates += 1
                # A roof the overview could not tell is measured now, by the vehicle there (the
                # leader would ask for it, and fly there for it).
                poi, shape = seen.pois[k], look.shapes[look.judgement.candidate]
                roof = roof_between(seen.shapes[poi.shape_index], seen.photo, shape, look.photo)
                if roof is None or roof > self.params.mission.assumed_roof_m:
                    crew.measured[k] = yield from measure_from_another_altitude(
                        self, k, poi, look, shape
                    )
        if not crew.decided:
            if self.candidates:
                # It found a match: the leader may choose it to photograph the target.
                self.event(Level.INFO, "waiting over its last look for the leader's decision")
                yield from self.wait_giving_way(
                    lambda: crew.decided, self.flight.land_timeout_s * 10
                )
            else:
                # Another may find it: this one may take a side photo of it meanwhile.
                yield from self._wait_aside(lambda: crew.decided, "the leader's decision")
        if crew.decided and crew.side_helper == self.index:
            yield from self._side_photo()
            if crew.side_result is not None:
                return "took a side photo for the model"
            if crew.side_job is None:
                return "was handed no side photo to take"
            return "could not take the side photo it was handed"
        if crew.decided and crew.modeller == self.index:
            yield from self.wait_until(lambda _t: crew.model_job is not None, 1e9)
            assert crew.model_job is not None
            found, survey_ = crew.model_job
            self.matched_poi, self.match_score = found.poi.index, found.score
            try:
                yield from photograph_and_model(self, found, survey_, layer)
            finally:
                crew.model_done = True
            if not self.model_built:
                raise self.end(Status.PARTIAL, f"target found; model not built: {self.no_model}")
            return "model built for vehicle 1"
        points = "point" if self.inspected == 1 else "points"
        return f"looked at {self.inspected} {points} of interest for vehicle 1"

    def _side_photo(self) -> Wait[None]:
        """The side photo the modeller hands over, once it does (nothing when it never
        does: its top photo showed no building, or it planned no such viewpoint)."""
        crew = self.crew
        modeller = crew.members[crew.modeller] if crew.modeller is not None else None
        try:
            yield from self._wait_aside(
                lambda: (
                    crew.side_job is not None
                    or crew.model_done
                    or modeller is None
                    or modeller.done
                ),
                "the side photo",
            )
            job = crew.side_job
            if job is None or crew.model_done:
                return
            plan, vp, colour = job
            plan.transit_m = max(plan.transit_m, self.layer_m())
            # handed over from where the photo was taken, before climbing back
            crew.side_result = yield from side_view(self, plan, vp, colour, climb=False)
            crew.side_done = True
            if crew.side_result is not None:
                x, y, _ = crew.side_result[1].pos_enu_m
                yield from self.move(
                    (x, y, plan.transit_m), None, f"climb from the {vp.name} viewpoint"
                )
        finally:
            crew.side_done = True

    def clear_aside(self, a: tuple[float, float], b: tuple[float, float], alt_m: float) -> bool:
        """Over ground a photo from above saw, and above every roof near the way by the
        margin (of unknown height too)."""
        return self._seen_way(a, b) and self.floor_along(a, b) <= alt_m

    def _wait_aside(self, until: Callable[[], bool], what: str) -> Wait[None]:
        """Wait for ``what`` on this member's layer, in no other's way down to a look or a
        viewpoint (and out of the way of any that still waits for it)."""
        last = self.last
        layer = self.layer_m()
        if last is not None and last.pos_enu_m[2] < layer - self.flight.arrive_radius_m:
            x, y, _ = last.pos_enu_m
            yield from self.move((x, y, layer), None, f"up to its layer, waiting for {what}")
        yield from self.wait_giving_way(until, self.flight.land_timeout_s * 10)

    def _standby_m(self) -> float:
        """Where a helper waits over home for the leader's survey: low, under every
        layer (a take-off straight up is clear: the vehicle refuses one that is not)."""
        return min(STANDBY_M, self.params.mission.overview_alt_m)

    def _called_off(self) -> bool:
        return self.crew.decided

    def go_home(self) -> Wait[None]:
        """Over every known roof to above home at this member's layer, then the landing's
        column claimed (the vehicle's RTL descends straight)."""
        last = self.last
        if last is None or last.landed:
            return
        layer = max(self.layer_m(), last.pos_enu_m[2])
        hx, hy = self.home_en_m
        yield from self.travel((hx, hy, layer), None, layer, "home")
        column = Claim.column((hx, hy), self.flight.arrive_radius_m, 0.0, layer, "landing")
        yield from self.claim(column, "landing")

    def outcome_for(self, status: Status, reason: str) -> Outcome:
        if self.index > 0 and status is Status.NO_MATCH:
            status = Status.COMPLETED  # a helper judges nothing: its part was the looking
        return super().outcome_for(status, reason)


def _where(member: FleetMember) -> tuple[float, float]:
    """Where ``member`` is (fleet frame): its last position, else its home."""
    last = member.last
    return (last.pos_enu_m[0], last.pos_enu_m[1]) if last is not None else member.home_en_m


def _distance(member: FleetMember, x: float, y: float) -> float:
    px, py = _where(member)
    return math.hypot(px - x, py - y)
