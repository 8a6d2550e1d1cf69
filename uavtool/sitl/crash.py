"""Crashes: the body sphere meeting an obstacle prism in flight, or the vehicle meeting the ground
too fast; the clearance record; the take-off-under-an-overhang check.

:class:`Collisions` only judges and remembers: ``Autopilot.crash`` acts on its verdict (says
it, cuts the motors, lets the wreck fall), so that this module knows nothing of modes or arming.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from uavtool.sitl.obstacles import ObstacleField, Prism
from uavtool.sitl.physics import Multicopter
from uavtool.sitl.state import Result, denied

CRASH_VERTICAL_SPEED_MS = 3.0
"""Meeting the ground armed and descending faster than this (m/s) is a crash. A normal landing
descends at LAND_SPEED: 0.5 m/s by default, 0.3-2 m/s in ArduCopter's documented range."""
CRASH_HORIZONTAL_SPEED_MS = 2.0
"""Meeting the ground armed and moving sideways faster than this (m/s) is a crash: the vehicle
tips over on its landing gear."""
CRASH_MIN_HEIGHT_M = 0.5
"""A touchdown is judged only after the vehicle has been at least this high since it left the
ground: turbulence lifting an idling vehicle by centimetres (≈ 2 cm per m/s of SIM_WIND_TURB)
and setting it down again is not a landing."""
CLEARANCE_RESOLUTION_M = 0.01
"""``closest_clearance_m`` is at most this much above the least clearance of the 50 Hz samples
(it is never below it): hovering beside a wall then costs no geometry. Collisions are exact."""


class Collisions:
    """The crash checks of a vehicle of body radius ``body_radius_m`` among ``obstacles``, and
    what they found: whether it crashed and why, and the closest it came to an obstacle."""

    def __init__(self, obstacles: Sequence[Prism], body_radius_m: float) -> None:
        self.obstacles = ObstacleField(obstacles)
        self.body_radius_m = body_radius_m
        self.has_obstacles = len(obstacles) > 0
        self.crashed = False
        self.crash_reason = ""
        """Why the vehicle crashed (the STATUSTEXT it sent), "" while it has not."""
        self.closest_clearance_m = math.inf
        """Least distance (m) between the body sphere's surface and any obstacle while flying
        (armed and off the ground) so far, to CLEARANCE_RESOLUTION_M; ≤ 0 after a collision;
        inf without obstacles (or before the first step in the air)."""
        self.closest_obstacle = ""
        """The obstacle ``closest_clearance_m`` was measured to ("" while it is inf)."""
        # Where the nearest obstacle distance was last measured (NED m), and how far (squared)
        # the vehicle may move from there before it must be measured again (< 0: at once).
        # The distance changes no faster than the vehicle moves, so far from obstacles the
        # check is a few multiplications per step.
        self._clearance_at = (0.0, 0.0, 0.0)
        self._clearance_free2_m2 = -1.0

    def record_crash(self, reason: str) -> None:
        """Remember the crash for good: only a restart (a new vehicle) forgets it."""
        self.crashed = True
        self.crash_reason = reason

    def check(self, vehicle: Multicopter) -> str | None:
        """Collision of the body sphere with an obstacle in flight, or a hard touchdown, after
        the armed ``vehicle``'s last step: the crash's STATUSTEXT, or None."""
        s = vehicle.state
        if self.has_obstacles and not s.on_ground:
            n, e, d = s.pos_ned_m
            at = self._clearance_at
            dn, de, dd = n - at[0], e - at[1], d - at[2]
            if dn * dn + de * de + dd * dd >= self._clearance_free2_m2:
                name = self._measure_clearance(n, e, d)
                if name is not None and self.closest_clearance_m < 0.0:
                    return f"Crash: collision with building {name!r}"
        touchdown = vehicle.touchdown
        if touchdown is not None and touchdown.peak_up_m >= CRASH_MIN_HEIGHT_M:
            vn, ve, vd = touchdown.vel_ned_ms
            horizontal_ms = math.hypot(vn, ve)
            if vd > CRASH_VERTICAL_SPEED_MS or horizontal_ms > CRASH_HORIZONTAL_SPEED_MS:
                speed_ms = math.hypot(horizontal_ms, vd)
                return f"Crash: hit the ground at {speed_ms:.1f} m/s"
        return None

    def _measure_clearance(self, n: float, e: float, d: float) -> str | None:
        """Measure the distance to the nearest obstacle at (n, e, d) (NED metres) and update
        ``closest_clearance_m``; the obstacle's name when it set a new record."""
        distance_m, prism = self.obstacles.nearest(e, n, -d)
        radius = self.body_radius_m
        clearance_m = distance_m - radius
        name = None
        if prism is not None and clearance_m < self.closest_clearance_m:
            name = self.closest_obstacle = prism.name
            self.closest_clearance_m = clearance_m
        # Measure again only where the distance may have fallen below the body radius or below
        # the record less its resolution: the distance changes no faster than the vehicle moves.
        needed_m = radius + max(self.closest_clearance_m - CLEARANCE_RESOLUTION_M, 0.0)
        free_m = distance_m - needed_m
        self._clearance_at = (n, e, d)
        self._clearance_free2_m2 = free_m * free_m if free_m > 0.0 else -1.0
        return name

    def takeoff_obstacle(self, pos_ned_m: Sequence[float], alt_m: float) -> Result | None:
        """DENIED if the body sphere, climbing straight up from ``pos_ned_m`` to ``alt_m``
        (m above home), would touch a prism."""
        if not self.has_obstacles:
            return None
        n, e, d = pos_ned_m
        up_m = -d
        hit = self.obstacles.first_above(
            e, n, from_up_m=up_m, to_up_m=alt_m, radius_m=self.body_radius_m
        )
        if hit is None:
            return None
        prism, distance_m = hit
        above_m = prism.base_m - up_m
        if above_m > 0.0:
            return denied(f"Takeoff: obstacle above at {above_m:.1f} m")
        # Not overhead but beside (or around) the vehicle: leaving the ground would touch it.
        return denied(f"Takeoff: obstacle {prism.name!r} within {max(distance_m, 0.0):.1f} m")
