"""A lawnmower survey: photograph a square straight down, lane by lane, and stitch the photos
into one map of the ground (a mosaic, on ``/mission/pictures``).

The lanes run north-south, the photos face north, and their spacing follows from the
camera (the first photo says its field of view) and the overlap asked for. The mosaic is a
north-up orthographic map of the ground plane: each of its cells takes its colour from the
photo whose centre is nearest to it (buildings lean away from each photo's centre, as in any
mosaic without a surface model).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from uavtool.api import (
    NADIR_DEG,
    Envelope,
    FlightMission,
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
    project,
)


@dataclass(frozen=True, slots=True)
class Survey:
    altitude_m: float = 60.0
    """Altitude above home of every lane; it must clear every roof in the square (the vehicle
    climbs to it straight above home, then flies the lanes at it)."""
    half_side_m: float = 40.0
    """The square reaches this far from home east, west, north and south."""
    overlap: float = 0.3
    """Fraction by which neighbouring photos overlap, along and across the lanes."""
    mosaic_m_per_px: float = 0.25
    """Ground size of one mosaic pixel."""

    def __post_init__(self) -> None:
        if not (self.altitude_m > 0 and self.half_side_m > 0 and self.mosaic_m_per_px > 0):
            raise ValueError("survey.altitude_m, half_side_m and mosaic_m_per_px must be > 0")
        if not 0.0 <= self.overlap < 0.95:
            raise ValueError("survey.overlap must be in [0, 0.95)")


@dataclass(frozen=True, slots=True)
class SurveyParams:
    survey: Survey = field(default_factory=Survey)
    flight: FlightParams = field(default_factory=FlightParams)


class SurveyMission(FlightMission):
    """Photograph a square lane by lane, straight down, and stitch the photos into a map."""

    params_type = SurveyParams

    params: SurveyParams

    def __init__(self, params: SurveyParams, inputs: MissionInputs) -> None:
        super().__init__(params, inputs)
        self.photos: list[Photo] = []

    @classmethod
    def envelope(cls, params: SurveyParams, intrinsics: Intrinsics) -> Envelope:
        s = params.survey
        return Envelope(
            altitude_m=s.altitude_m,
            distance_m=s.half_side_m * math.sqrt(2.0),
            why_up="for its lanes",
            why_out="the square's corners are",
            shrink_up="survey.altitude_m",
            shrink_out="survey.half_side_m",
        )

    def fly(self) -> Wait[str]:
        s = self.params.survey
        yield from self.arm_and_take_off(s.altitude_m)
        yield from self.move((0.0, 0.0, s.altitude_m), 0.0, "survey altitude, facing north")
        first = yield from self.photo("home", NADIR_DEG)
        stops = lanes(s, first.intrinsics)
        self.event(Level.INFO, f"{len(stops)} photos in {len({x for x, _ in stops})} lanes")
        for k, (x, y) in enumerate(stops):
            yield from self.move((x, y, s.altitude_m), 0.0, f"photo {k + 1} of {len(stops)}")
            self.photos.append((yield from self.photo(f"survey-{k}", NADIR_DEG)))
        image, covered = mosaic(self.photos, s)
        self.emit(Picture("mosaic", png_encode(image)))
        self.emit(Result("mosaic", {"photos": len(self.photos), "covered": round(covered, 4)}))
        if covered < 0.99:
            raise self.end(Status.PARTIAL, f"the mosaic covers {covered:.1%} of the square")
        return f"mosaic of {len(self.photos)} photos"


def lanes(s: Survey, intrinsics: Intrinsics) -> list[tuple[float, float]]:
    """Where to photograph (east, north): lanes west to east, alternately north- and
    southbound, each photo's ground footprint overlapping its neighbours' by ``overlap``."""
    across = 2.0 * s.altitude_m * math.tan(math.radians(intrinsics.hfov_deg) / 2.0)
    along = 2.0 * s.altitude_m * math.tan(math.radians(intrinsics.vfov_deg) / 2.0)
    xs = _centres(s.half_side_m, across * (1.0 - s.overlap), across)
    ys = _centres(s.half_side_m, along * (1.0 - s.overlap), along)
    stops = []
    for i, x in enumerate(xs):
        stops += [(x, y) for y in (ys if i % 2 == 0 else ys[::-1])]
    return stops


def _centres(half_m: float, step_m: float, footprint_m: float) -> list[float]:
    """Photo centres along one axis so that footprints cover [-half, half]."""
    n = max(1, math.ceil((2.0 * half_m - footprint_m) / step_m) + 1)
    span = (n - 1) * step_m
    return [-span / 2.0 + i * step_m for i in range(n)]


def mosaic(photos: list[Photo], s: Survey) -> tuple[np.ndarray, float]:
    """The north-up map of the ground plane (H, W, 3 uint8) and the fraction of it covered."""
    side = round(2.0 * s.half_side_m / s.mosaic_m_per_px)
    centres = (np.arange(side) + 0.5) * s.mosaic_m_per_px - s.half_side_m
    east, north = np.meshgrid(centres, centres[::-1])  # row 0 is the north edge
    ground = np.stack([east.ravel(), north.ravel(), np.zeros(east.size)], axis=1)
    image = np.zeros((side * side, 3), np.uint8)
    best = np.full(side * side, np.inf)  # squared distance to the chosen photo's centre
    for photo in photos:
        uvz = project(ground, photo.pose, photo.intrinsics)
        u, v, z = uvz[:, 0], uvz[:, 1], uvz[:, 2]
        w, h = photo.intrinsics.width_px, photo.intrinsics.height_px
        inside = (z > 0) & (u >= 0) & (u <= w - 1) & (v >= 0) & (v <= h - 1)
        cx, cy, _ = photo.pose.pos_enu_m
        d2 = (ground[:, 0] - cx) ** 2 + (ground[:, 1] - cy) ** 2
        take = inside & (d2 < best)
        rows = np.rint(v[take]).astype(int)
        cols = np.rint(u[take]).astype(int)
        image[take] = photo.image_rgb[rows, cols]
        best[take] = d2[take]
    covered = float(np.isfinite(best).mean())
    return image.reshape(side, side, 3), covered
