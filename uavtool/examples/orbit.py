"""An orbit: circle a point (a building) and photograph it every few degrees, the camera
aimed at it — the photos a photogrammetry tool needs for a 3D model.

The vehicle climbs straight above home to the orbit's altitude, flies there to the first
stop, and goes round at that altitude: the altitude must clear every roof on the circle and
on the way to it. Each photo faces the centre, the gimbal pitched down to the aim point.
Without a gimbal (``--no-gimbal``) the photos look straight down and the orbit ends partial.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uavtool.api import (
    NADIR_DEG,
    Envelope,
    FlightMission,
    FlightParams,
    Intrinsics,
    Result,
    Status,
    Wait,
)


@dataclass(frozen=True, slots=True)
class Orbit:
    east_m: float = 0.0
    """The centre of the circle, east of home …"""
    north_m: float = 0.0
    """… and north of it."""
    radius_m: float = 30.0
    altitude_m: float = 30.0
    """Altitude above home of the whole orbit (it must clear every roof on the way)."""
    aim_m: float = 0.0
    """Height above home of the point the camera aims at (e.g. half the building's height)."""
    step_deg: float = 45.0
    """A photo every this many degrees round the circle, from north, clockwise."""

    def __post_init__(self) -> None:
        if not (self.radius_m > 0 and self.altitude_m > 0 and 0 < self.step_deg <= 360):
            raise ValueError("orbit.radius_m and altitude_m must be > 0, step_deg in (0, 360]")
        if self.aim_m >= self.altitude_m:
            raise ValueError("orbit.aim_m must be below orbit.altitude_m")


@dataclass(frozen=True, slots=True)
class OrbitParams:
    orbit: Orbit = field(default_factory=Orbit)
    flight: FlightParams = field(default_factory=FlightParams)


class OrbitMission(FlightMission):
    """Circle a point and photograph it every few degrees, the camera aimed at it."""

    params_type = OrbitParams

    params: OrbitParams

    @classmethod
    def envelope(cls, params: OrbitParams, intrinsics: Intrinsics) -> Envelope:
        o = params.orbit
        return Envelope(
            altitude_m=o.altitude_m,
            distance_m=math.hypot(o.east_m, o.north_m) + o.radius_m,
            why_up="for its orbit",
            why_out="the orbit reaches",
            shrink_up="orbit.altitude_m",
            shrink_out="orbit.radius_m",
        )

    def fly(self) -> Wait[str]:
        o = self.params.orbit
        stops = round(360.0 / o.step_deg)
        pitch = -math.degrees(math.atan2(o.altitude_m - o.aim_m, o.radius_m))
        yield from self.arm_and_take_off(o.altitude_m)
        taken = []
        for k in range(stops):
            bearing = k * o.step_deg  # from the centre to the vehicle, clockwise from north
            x = o.east_m + o.radius_m * math.sin(math.radians(bearing))
            y = o.north_m + o.radius_m * math.cos(math.radians(bearing))
            facing = (bearing + 180.0) % 360.0  # back at the centre
            yield from self.move((x, y, o.altitude_m), facing, f"orbit {bearing:g}°")
            photo = yield from self.photo(
                f"orbit-{bearing:g}", pitch if self.flight.gimbal else NADIR_DEG
            )
            taken.append(photo.frame_index)
        self.emit(Result("orbit", {"frames": taken, "pitch_deg": round(pitch, 2)}))
        if not self.flight.gimbal:
            raise self.end(Status.PARTIAL, f"{stops} photos straight down: no gimbal to aim")
        return f"{stops} photos round ({o.east_m:g}, {o.north_m:g})"
