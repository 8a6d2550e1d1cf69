"""The lawnmower survey of :mod:`uavtool.examples.survey`, flown by a fleet: the square is cut
into one strip per vehicle (west to east), each vehicle photographs its strip at its own layer,
and the last to finish stitches every photo into one map.

A fleet mission in a few lines: the members are one class (:class:`FleetMember`), live in
the fleet's frame (around the first vehicle's home), take off with
:meth:`~FleetMember.take_off`, move as any mission does (every move claims its airspace
first, so the vehicles keep ``fleet.separation_m`` apart) and share their photos on the
crew's board. ``uavtool fly --vehicles 3 --mission fleet-survey`` flies it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uavtool.api import (
    NADIR_DEG,
    Envelope,
    FleetMember,
    FleetParams,
    FlightParams,
    Intrinsics,
    Level,
    MissionInputs,
    Photo,
    Picture,
    Result,
    Status,
    Wait,
    png_encode,
)
from uavtool.examples.survey import Survey, SurveyMission, mosaic


@dataclass(frozen=True, slots=True)
class FleetSurveyParams:
    survey: Survey = field(default_factory=Survey)
    flight: FlightParams = field(default_factory=FlightParams)
    fleet: FleetParams = field(default_factory=FleetParams)


class FleetSurveyMission(FleetMember):
    """Photograph a square with a fleet, a strip per vehicle, and stitch one map."""

    params_type = FleetSurveyParams
    params: FleetSurveyParams

    def __init__(self, params: FleetSurveyParams, inputs: MissionInputs) -> None:
        super().__init__(params, inputs)
        self.photos: list[Photo] = []

    @classmethod
    def envelope(cls, params: FleetSurveyParams, intrinsics: Intrinsics) -> Envelope:
        """The one-vehicle survey's: the same square at the same altitude (the layers above
        it are a few metres more)."""
        return SurveyMission.envelope(params, intrinsics)  # type: ignore[arg-type]

    def base_layer_m(self) -> float:
        return self.params.survey.altitude_m

    def fly(self) -> Wait[str]:
        s = self.params.survey
        layer = self.layer_m()
        hx, hy = self.home_en_m
        yield from self.take_off(layer)
        yield from self.move((hx, hy, layer), 0.0, "facing north")
        first = yield from self.photo("home", NADIR_DEG)
        stops = strip_stops(s, first.intrinsics, layer, self.index, self.crew.size)
        self.event(Level.INFO, f"strip {self.index + 1} of {self.crew.size}: {len(stops)} photos")
        for k, (x, y) in enumerate(stops):
            yield from self.move((x, y, layer), 0.0, f"photo {k + 1} of {len(stops)}")
            self.photos.append((yield from self.photo(f"survey-{self.index + 1}-{k}", NADIR_DEG)))
        board = self.crew.board
        board.setdefault("photos", []).extend(self.photos)
        board["strips done"] = board.get("strips done", 0) + 1
        self.emit(Result("strip", {"vehicle": self.index + 1, "photos": len(self.photos)}))
        if board["strips done"] < self.crew.size:
            return f"strip {self.index + 1}: {len(self.photos)} photos"
        image, covered = mosaic(board["photos"], s)
        self.emit(Picture("mosaic", png_encode(image)))
        self.emit(Result("mosaic", {"photos": len(board["photos"]), "covered": round(covered, 4)}))
        if covered < 0.99:
            raise self.end(Status.PARTIAL, f"the mosaic covers {covered:.1%} of the square")
        return f"the last strip; mosaic of {len(board['photos'])} photos"


def strip_stops(
    s: Survey, intrinsics: Intrinsics, altitude_m: float, index: int, count: int
) -> list[tuple[float, float]]:
    """Where member ``index`` of ``count`` photographs (fleet frame, east and north): lanes
    across its strip of the square, west to east, alternately north- and southbound, each
    photo's footprint at ``altitude_m`` overlapping its neighbours' by ``overlap``."""
    across = 2.0 * altitude_m * math.tan(math.radians(intrinsics.hfov_deg) / 2.0)
    along = 2.0 * altitude_m * math.tan(math.radians(intrinsics.vfov_deg) / 2.0)
    width = 2.0 * s.half_side_m / count
    west = -s.half_side_m + index * width
    xs = _centres(west, west + width, across * (1.0 - s.overlap), across)
    ys = _centres(-s.half_side_m, s.half_side_m, along * (1.0 - s.overlap), along)
    stops = []
    for i, x in enumerate(xs):
        stops += [(x, y) for y in (ys if i % 2 == 0 else ys[::-1])]
    return stops


def _centres(lo_m: float, hi_m: float, step_m: float, footprint_m: float) -> list[float]:
    """Photo centres along one axis so that footprints cover [lo, hi]."""
    n = max(1, math.ceil((hi_m - lo_m - footprint_m) / step_m) + 1)
    span = (n - 1) * step_m
    mid = (lo_m + hi_m) / 2.0
    return [mid - span / 2.0 + i * step_m for i in range(n)]
