"""Where ArduCopter points its nose while it flies to a position target with no yaw given:
``WP_YAW_BEHAVIOR`` (0 never change, 1 face the next waypoint, 2 the same except in RTL,
3 along the ground course). In GUIDED it faces the target once it is farther than
``WPNAV_YAW_DIST_MIN``-like 2 m, and holds its heading for closer targets."""

from __future__ import annotations

import math

NEVER_CHANGE = 0
LOOK_AHEAD = 3
MIN_DISTANCE_M = 2.0


def travel_yaw_deg(
    behaviour: int, *, from_ne_m: tuple[float, float], to_ne_m: tuple[float, float]
) -> float | None:
    """The heading to hold on the way (degrees, [0, 360)), or None to keep the current one."""
    if behaviour == NEVER_CHANGE:
        return None
    dn, de = to_ne_m[0] - from_ne_m[0], to_ne_m[1] - from_ne_m[1]
    if math.hypot(dn, de) < MIN_DISTANCE_M:
        return None
    return math.degrees(math.atan2(de, dn)) % 360.0
