"""The built-in mission (paper section V): search the area for the building in the target
picture, then photograph it from above, the front and the right and build its 3D model.

It is a :class:`~uavtool.mission.base.FlightMission` like any plug-in: the scenario's steps
(:mod:`uavtool.mission.scenario` and the modules it calls) use the base's helpers, and this
class adds what the search knows about the space it flies in — which roofs are measured,
which are not — so that no way crosses near a roof lower than the altitude that clears it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, ClassVar

from uavtool.camera import Intrinsics
from uavtool.mission.analysis import shows_higher_part, stepped, target_shapes
from uavtool.mission.base import Envelope, FlightMission, MissionInputs, Wait
from uavtool.mission.errors import MissionInputError
from uavtool.mission.outputs import (
    Level,
    ModelBuilt,
    Outcome,
    Output,
    Plan,
    Shapes,
    Status,
    Vec3,
    Viewpoints,
)
from uavtool.mission.params import Params
from uavtool.mission.peek import Peek, peek
from uavtool.mission.unknown import Overview, Unknown
from uavtool.nav.geometry import (
    point_in_polygon,
    point_segment_distance,
    segment_polygon_distance,
)
from uavtool.vision.vectorize import enclosed_openings

if TYPE_CHECKING:
    from uavtool.mission.looks import Found, Look
    from uavtool.mission.observations import Photo
    from uavtool.mission.outputs import PointOfInterest
    from uavtool.mission.search import Inspector
    from uavtool.mission.sides import HandedSide, SidePlan
    from uavtool.mission.survey import Survey
    from uavtool.nav import Viewpoint
    from uavtool.vision import Shape


class SearchMission(FlightMission):
    """Find the building in the target picture, photograph it from three sides, model it.

    One flight of the built-in mission. ``inputs.target_rgb`` is the target building
    photographed from above; its largest shape is what the mission looks for.
    Raises :class:`MissionInputError` if there is no target picture or it holds no shape.
    """

    name: ClassVar[str] = "search"
    params_type: ClassVar[type[Any]] = Params
    needs_target: ClassVar[bool] = True
    flight_group: ClassVar[str] = "mission"

    def __init__(self, params: Params, inputs: MissionInputs) -> None:
        super().__init__(params, inputs)
        self.params: Params = params
        if inputs.target_rgb is None:
            raise MissionInputError("the search mission needs a target picture")
        self.target_shapes, self.target = target_shapes(params, inputs.target_rgb)
        self.visited: list[int] = []
        self.matched_poi = -1
        self.match_score = 0.0
        self.model_built = False
        self.target_stepped = stepped(inputs.target_rgb, self.target)
        """Whether the target picture shows parts at several heights (then a match's outline
        is not compared with it: `uavtool.mission.analysis.judge`)."""
        h, w = inputs.target_rgb.shape[:2]
        self.target_nadir_px = ((w - 1) / 2.0, (h - 1) / 2.0)
        """The target picture's point straight below its camera: its centre (a picture
        taken looking straight down)."""
        self.target_tiers = shows_higher_part(
            params, inputs.target_rgb, self.target, self.target_nadir_px
        )
        """Whether the target picture shows a higher part's walls inside its roof, as long
        as an edge (`shows_higher_part`): a building that matches as well and, photographed
        as the picture was, shows none is not the target (`uavtool.mission.settle`)."""
        self.target_openings = enclosed_openings(
            inputs.target_rgb, self.target, least_px=params.vectorize.min_hole_area_px
        )
        """How many openings the target picture shows inside its outline
        (`enclosed_openings`): what tells apart two buildings that match it as well."""
        self.plan: Plan | None = None
        self.transit_m: float | None = None
        """The altitude that clears every known roof (once the survey has measured them)."""
        self.ceiling_m: float | None = None
        """The second overview's altitude: every roof it showed is below it."""
        self.seen_ground: tuple[tuple[float, float], ...] | None = None
        """The ground the second overview showed (its frame's corners on the ground): a
        building standing there would show in it. None before it is taken."""
        self.peeks: list[Peek] = []
        """Photos straight down from the ceiling beyond that ground
        (:func:`uavtool.mission.peek.peek`): where they show no building near a place or a
        way, it is seen free too."""
        self.from_above: list[Photo] = []
        """The photos straight down from the ceiling (the overviews, the tour measuring
        roofs, the peeks): what parallax against them shows lies on the ground is no
        building (:func:`~uavtool.mission.ground.standing_regions`)."""
        self.higher_parts: dict[int, bool | None] = {}
        """Whether each point of interest's roof was seen to show a higher part's walls
        (None: no photo could tell), once the target picture shows one and it had to be
        told from another building (`uavtool.mission.settle`)."""
        self.unknown: dict[int, Unknown] = {}
        """Where buildings of unknown height may stand, and the highest each roof may be
        there (by the overview shape's index; an obstacle's is negative): a way near one
        crosses over that by the margin."""
        self.roofs: tuple[tuple[tuple[tuple[float, float], ...], float], ...] = ()
        """Every measured roof: (footprint, height above home)."""
        self.overview: Overview | None = None
        """The higher overview's roofs as the survey left them, for a look to measure
        more of (None before the survey, or when it measured every roof)."""
        self.viewpoints: Viewpoints | None = None
        self.model: ModelBuilt | None = None
        self._frames_seen = 0
        self.no_model = "unknown"
        """Why no model was built (for a PARTIAL outcome)."""

    # --- the mission's part of the base's contract ---------------------------------------------

    def first_outputs(self) -> list[Output]:
        return [Shapes(-1, "target", self.target_shapes)]

    def fly(self) -> Wait[str]:
        from uavtool.mission.scenario import fly  # noqa: PLC0415 - the scenario uses this module

        yield from fly(self)
        if not self.model_built:
            raise self.end(Status.PARTIAL, f"target found; model not built: {self.no_model}")
        return "model built"

    def above(self, altitude_m: float) -> float:
        """The altitude this vehicle crosses at where the way asks for ``altitude_m`` (a
        fleet's members each cross at a layer of their own)."""
        return altitude_m

    def take_off_to(self, alt_m: float) -> Wait[None]:
        """Take off to ``alt_m`` above home (a fleet's member claims the airspace first)."""
        yield from self.arm_and_take_off(alt_m)

    def inspector(self, seen: Survey, transit_m: float) -> Inspector | None:  # noqa: ARG002
        """Who looks at the points of interest: None, this vehicle (a fleet's leader hands
        them out)."""
        return None

    def searched(self, found: Found | None) -> None:
        """The search has decided (a fleet calls the others off here)."""

    def measure_roof(
        self, k: int, poi: PointOfInterest, look: Look, shape: Shape
    ) -> Wait[float | None]:
        """The height of a matched roof the overview could not tell (a fleet's helper that
        took the look has measured it already)."""
        from uavtool.mission.search import measure_from_another_altitude  # noqa: PLC0415

        return (yield from measure_from_another_altitude(self, k, poi, look, shape))

    def standing_vehicles(self) -> list[tuple[tuple[tuple[float, float], ...], float]]:
        """Where other vehicles stand, or will land, as obstacles the model's viewpoints keep
        clear of (each a footprint and a height, as a building's): none for one vehicle (a
        fleet's member: the others' homes)."""
        return []

    def side_elsewhere(
        self,
        plan: SidePlan,
        viewpoints: tuple[Viewpoint, ...],
        colour_rgb: tuple[int, int, int],
    ) -> HandedSide | None:
        """Hand one of the side photos planned (``viewpoints``) to another vehicle, which
        takes it while this one takes the other; None when no other vehicle takes one (one
        vehicle takes both; a fleet's member hands one to a helper still flying)."""
        del plan, viewpoints, colour_rgb
        return None

    def model_target(self, found: Found, seen: Survey, transit_m: float) -> Wait[None]:
        """Photograph the target from three sides and build its model (a fleet's leader
        hands this to the vehicle at the target)."""
        from uavtool.mission.modelling import photograph_and_model  # noqa: PLC0415 - uses this

        yield from photograph_and_model(self, found, seen, transit_m)

    def go_home(self) -> Wait[None]:
        if self.transit_m is not None:
            # The vehicle's RTL flies straight home at its own altitude: go home over every
            # known roof first.
            home = (0.0, 0.0, self.transit_m)
            yield from self.travel(home, None, self.transit_m, "home")

    def outcome_for(self, status: Status, reason: str) -> Outcome:
        return Outcome(
            status,
            reason,
            tuple(self.visited),
            self.matched_poi,
            self.match_score,
            self.model_built,
        )

    @classmethod
    def envelope(cls, params: Any, intrinsics: Intrinsics) -> Envelope:
        from uavtool.mission.survey import overview_ceiling_m  # noqa: PLC0415

        return Envelope(
            altitude_m=overview_ceiling_m(params.mission, intrinsics),
            distance_m=float(params.mission.search_radius_m) * math.sqrt(2.0),
            why_up="for its second overview",
            why_out="the search square's corners are",
            shrink_up="mission.search_radius_m or mission.assumed_roof_m",
            shrink_out="mission.search_radius_m (side photos of a building at the edge fly "
            "farther)",
        )

    # --- flying near roofs ---------------------------------------------------------------------

    def travel(
        self, pos_enu_m: Vec3, heading_deg: float | None, transit_m: float, what: str
    ) -> Wait[None]:
        """Fly to a position over every known roof: straight up to ``transit_m`` (or the
        destination's altitude, if higher) when below it, across at that altitude, then
        straight to the destination. Below the ceiling over ground no photo from above saw,
        a look straight down from the ceiling comes first; where it shows a building near,
        the vehicle stops at the ceiling over the destination."""
        p = self.params.mission
        x, y, z = pos_enu_m
        if (
            self.ceiling_m is not None
            and z < self.ceiling_m - p.arrive_radius_m
            and not self.over_seen_ground(x, y)
            and not (yield from peek(self, x, y, what, f"peek-{len(self.peeks) + 1}"))
        ):  # nothing is known below: the ceiling is as low as it goes there
            ceiling = self.above(self.ceiling_m)
            yield from self.move((x, y, ceiling), heading_deg, f"{what}: at the ceiling")
            return
        cruise = max(transit_m, z)
        here = self.last.pos_enu_m if self.last is not None else (x, y, cruise)
        over = self._over_unknown(here, (x, y))
        if over > cruise:
            cruise = self.above(over)
            self.event(
                Level.INFO,
                f"{what}: a roof of unknown height near the way: across at {cruise:.1f} m",
            )
        if (
            self.ceiling_m is not None
            and cruise < self.ceiling_m
            and not self._seen_way((here[0], here[1]), (x, y))
        ):
            cruise = self.above(self.ceiling_m)
            self.event(
                Level.INFO,
                f"{what}: the way leaves the ground the overview saw: across at {cruise:.1f} m",
            )
        if math.hypot(here[0] - x, here[1] - y) > p.arrive_radius_m:
            if here[2] < cruise - p.arrive_radius_m:
                yield from self.move((here[0], here[1], cruise), None, f"climb to {cruise:.1f} m")
            yield from self.move((x, y, cruise), None, f"{what}: across at {cruise:.1f} m")
        yield from self.move(pos_enu_m, heading_deg, what)

    def in_seen_ground(self, p: tuple[float, float]) -> bool:
        """Whether the second overview saw the ground near (x, y) (:meth:`_seen_margin_m`):
        any building standing there would show in it (everywhere before it is taken)."""
        if self.seen_ground is None:
            return True
        ring = self.seen_ground
        need_m = self._seen_margin_m()
        return point_in_polygon(p, ring) and all(
            point_segment_distance(p, ring[i], ring[(i + 1) % len(ring)]) >= need_m
            for i in range(len(ring))
        )

    def _seen_margin_m(self) -> float:
        """How far inside what a photo showed a place must be for every building near it
        to have shown: the safety margin and the arrival radius."""
        return self.params.viewpoints.safety_margin_m + self.params.mission.arrive_radius_m

    def over_seen_ground(self, x: float, y: float) -> bool:
        """Whether no building stands within the safety margin (and the arrival radius) of
        the vertical through (x, y) but those the mission knows: the overview saw the
        ground there, or a photo straight down from the ceiling (:attr:`peeks`) shows none
        near it."""
        return self._seen_way((x, y), (x, y))

    def _seen_way(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """Whether the straight way from ``a`` to ``b`` keeps over ground the overview saw
        (its frame's ground is convex: a way between two places in it stays in it), or a
        photo from the ceiling shows no building within the margin of it, or the way is
        one part and then the other (split every metre)."""
        if self._seen_part(a, b):
            return True
        n = int(math.hypot(b[0] - a[0], b[1] - a[1]))
        for i in range(1, n):
            t = i / n
            mid = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
            if self._seen_part(a, mid) and self._seen_part(mid, b):
                return True
        return False

    def _seen_part(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        if self.in_seen_ground(a) and self.in_seen_ground(b):
            return True
        return any(peek.clear_m(a, b) >= self._seen_margin_m() for peek in self.peeks)

    def floor_at(self, x: float, y: float) -> float:
        """The lowest altitude over (x, y) that keeps the safety margin (and the arrival
        radius) above every roof within the margin of it, and above the highest a roof of
        unknown height there may be. (A look aimed at one tier of a stepped tower must not
        descend onto another.)"""
        return self.floor_along((x, y), (x, y))

    def floor_along(self, a: tuple[float, float], b: tuple[float, float]) -> float:
        """The lowest altitude that keeps the safety margin (and the arrival radius) above
        every roof within the margin of the ground track from ``a`` to ``b``, known or of
        unknown height (`floor_at` along a line)."""
        margin_m = self.params.viewpoints.safety_margin_m
        need = 0.0
        for footprint, roof_m in self.roofs:
            if segment_polygon_distance(a, b, footprint) <= margin_m:
                need = max(need, roof_m + margin_m + self.params.mission.arrive_radius_m)
        return max(need, self._over_unknown((a[0], a[1], 0.0), b))

    def learn_roof(
        self, index: int, footprint: tuple[tuple[float, float], ...], roof_m: float
    ) -> None:
        """A roof of unknown height (overview shape ``index``) measured at last. What of
        its region it leaves unexplained (a building of no building colour merged with it
        in the overview) may stand as high as a building of unknown height there may."""
        place = self.unknown.pop(index, None)
        self.roofs = (*self.roofs, (footprint, roof_m))
        ov = self.overview
        if place is None or ov is None or not 0 <= index < len(ov.shapes):
            return
        ov.roofs_m[index] = roof_m
        for rest in ov.rest_of(index, roof_m):
            key = min([-1_000_000, *ov.others]) - 1  # past the survey's obstacles
            self.unknown[key] = ov.place(rest)
            ov.others[key] = rest

    def measure_near(self, x: float, y: float, photo: Photo, shapes: tuple[Shape, ...]) -> bool:
        """Measure, against ``photo`` (a look from above; its building ``shapes``), the roofs
        of unknown height that the floor over (x, y) counts with; whether any was."""
        from uavtool.mission.measure import measure_in_the_way  # noqa: PLC0415 - uses this

        return measure_in_the_way(self, x, y, photo, shapes)

    def _over_unknown(self, here: Vec3, there: tuple[float, float]) -> float:
        """The altitude that clears, by the margin, the highest every building of unknown
        height within the safety margin of the ground track from ``here`` to ``there`` may
        be (0 when none is)."""
        margin_m = self.params.viewpoints.safety_margin_m
        a = (here[0], here[1])
        return max(
            (
                self._clear_of(top)
                for top in (
                    place.top_m(lambda ring: segment_polygon_distance(a, there, ring) <= margin_m)
                    for place in self.unknown.values()
                )
                if top is not None
            ),
            default=0.0,
        )

    def _clear_of(self, upper_m: float) -> float:
        """The altitude that keeps the safety margin, and the arrival radius, over a roof of
        unknown height that may be ``upper_m`` high; never above the ceiling (every roof the
        second overview showed is below it)."""
        p = self.params
        need = upper_m + p.viewpoints.safety_margin_m + p.mission.arrive_radius_m
        return need if self.ceiling_m is None else min(need, self.ceiling_m)
