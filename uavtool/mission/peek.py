"""Looking before going where the overview did not reach.

The second overview shows every building standing on the ground in its frame, so the mission
knows the space over that ground (:meth:`~uavtool.mission.mission.SearchMission.in_seen_ground`).
Beyond it, nothing was seen, and nothing is known to be free. A side camera that must stand
there first looks straight down from the ceiling over the place. A building standing on the
ground shows in a nadir photo as a region that, carried to the ground plane, holds its
footprint: its roof and walls land further from the nadir than its base, never nearer. So
where no region comes within the safety margin of a vertical, or of a straight way, no
building stands within it, at any height, and the photo serves every place and way in its
frame (:class:`Peek`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from uavtool.mission.ground import standing_regions
from uavtool.mission.looks import photo_shapes
from uavtool.mission.observations import Photo
from uavtool.mission.outputs import Level
from uavtool.nav import NavError, frame_on_plane, ground_point
from uavtool.nav.geometry import point_in_polygon, segment_polygon_distance
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import not_ground_regions

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission
    from uavtool.vision import Shape

Point = tuple[float, float]
Ring = tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class Peek:
    """What a photo straight down showed: its frame on the ground, and every region that is
    not ground carried to the ground plane (each holds the footprint of what it shows)."""

    frame: Ring
    buildings: tuple[Ring, ...]

    @classmethod
    def of(
        cls, photo: Photo, params: VectorizeParams, regions: tuple[Shape, ...] | None = None
    ) -> Peek | None:
        """None for a photo that is not straight down (a pixel above the horizon).
        ``regions``: what in it is not ground (by default, everything not of the ground's
        colour: `not_ground_regions`)."""
        k = photo.intrinsics
        if regions is None:
            regions = not_ground_regions(photo.image_rgb, params)
        try:
            frame = frame_on_plane(photo.pose, k)
            buildings = tuple(
                tuple(ground_point(u, v, photo.pose, k) for u, v in region.polygon_px.tolist())
                for region in regions
                if region.area_px >= params.min_area_px
            )
        except NavError:
            return None
        return cls(frame, buildings)

    def clear_m(self, a: Point, b: Point | None = None) -> float:
        """How far the vertical through ``a`` (or the way from ``a`` to ``b``) is from any
        building the photo shows; 0 when it leaves the frame (a region cut by the frame may
        go on beyond it, no nearer than the frame's edge)."""
        b = a if b is None else b
        if not (point_in_polygon(a, self.frame) and point_in_polygon(b, self.frame)):
            return 0.0
        n = len(self.frame)
        edges = [(self.frame[i], self.frame[(i + 1) % n]) for i in range(n)]
        return min(
            *(segment_polygon_distance(a, b, edge) for edge in edges),
            *(segment_polygon_distance(a, b, ring) for ring in self.buildings if len(ring) >= 3),
        )


def peek(m: SearchMission, x: float, y: float, what: str, tag: str) -> Wait[bool]:
    """Whether a camera may stand over (x, y), beyond the ground the overview saw: across
    at the ceiling to over it, a photo straight down, and no building within the safety
    margin (and the arrival radius) of the vertical. The photo is kept: every place and way
    it shows clear needs no other."""
    assert m.ceiling_m is not None
    yield from m.travel((x, y, m.ceiling_m), None, m.ceiling_m, f"over the {what}, looking down")
    photo = yield from m.photo(tag, -90.0)
    photo_shapes(m, photo)  # what it shows, as for every photo (viewers, re-analysis)
    # A road or a lawn is no building: parallax against the photos from the ceiling tells.
    # The roofs measured stand; what was measured at the ground's height is no roof.
    standing = [(footprint, roof_m) for footprint, roof_m in m.roofs if roof_m > 0.0]
    regions = standing_regions(m, photo, m.from_above, standing)
    m.from_above.append(photo)
    seen = Peek.of(photo, m.params.vectorize, regions)
    if seen is not None:
        m.peeks.append(seen)
    if m.over_seen_ground(x, y):
        m.event(Level.INFO, f"{what}: beyond the overview's ground; no building near it below")
        return True
    near_m = 0.0 if seen is None else seen.clear_m((x, y))
    m.event(
        Level.WARNING,
        f"{what}: beyond the overview's ground, and a building may stand {near_m:.1f} m from "
        "it: no photo from there",
    )
    return False
