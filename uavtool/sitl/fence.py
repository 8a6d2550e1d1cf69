"""The geofence, as ArduCopter's AC_Fence keeps it: a maximum altitude and a circle around home.

It is enforced twice. A guided target outside it is refused before the vehicle flies there; and
the vehicle's *position* is checked every physics step, in every mode, so that what no target
check can see (a velocity stream, an AUTO mission, wind) still meets it. A new breach triggers
``FENCE_ACTION``; a breach that carries on 20 m further is a new breach again (ArduPilot's
backup fences), so a vehicle told to fly on after a breach is turned back once more. A mode
change during a breach (a ground station re-taking control, or the breach's own action) starts
ArduCopter's manual recovery: for 10 s new breaches are noted but not acted on, then the
backup fences hold again ("Manual recovery started"). Under velocity control the vehicle does
not reach the fence at all: :mod:`~uavtool.sitl.avoid` stops it short, as ArduCopter's
AC_Avoid does.

This module only judges and remembers; ``Autopilot`` acts on a :class:`Breach`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntFlag

from uavtool.sitl.params import ParamStore
from uavtool.sitl.state import Mode, Result, denied


class FenceType(IntFlag):
    """FENCE_TYPE bits (AC_FENCE_TYPE_*); polygon and minimum altitude are not simulated."""

    ALT_MAX = 1
    CIRCLE = 2
    POLYGON = 4
    ALT_MIN = 8


_SIMULATED = FenceType.ALT_MAX | FenceType.CIRCLE
GIVE_UP_DISTANCE_M = 100.0
"""Further than this outside the fence, the action is LAND whatever FENCE_ACTION says
(AC_FENCE_GIVE_UP_DISTANCE): flying back would take too long."""
BACKUP_DISTANCE_M = 20.0
"""A breach that goes on this much further than where it began triggers the action again."""
MANUAL_RECOVERY_S = 10.0
"""After a mode change during a breach, new breaches are not acted on for this long
(AC_FENCE_MANUAL_RECOVERY_TIME_MIN)."""

# FENCE_ACTION → mode: 1 RTL (or LAND), 2 always LAND, 3 SmartRTL or RTL, 4 BRAKE or LAND,
# 5 SmartRTL or LAND; this vehicle has no SmartRTL, so 3 falls back to RTL and 5 to LAND.
_ACTION_MODES = {1: Mode.RTL, 2: Mode.LAND, 3: Mode.RTL, 4: Mode.BRAKE, 5: Mode.LAND}
_NAMES = {FenceType.ALT_MAX: "Max Alt", FenceType.CIRCLE: "Circle"}


@dataclass(frozen=True, slots=True)
class Breach:
    """A new breach: which fences (FenceType bits), how far outside (m), and the mode that
    FENCE_ACTION asks for (None: report only)."""

    types: FenceType
    distance_m: float
    mode: Mode | None

    @property
    def text(self) -> str:
        names = ", ".join(name for bit, name in _NAMES.items() if self.types & bit)
        return f"Fence breached: {names}"


_NONE = FenceType(0)


class Fence:
    """FENCE_* parameters applied to positions in metres NED around home."""

    def __init__(self, params: ParamStore) -> None:
        self.params = params
        self.breaches = FenceType(0)
        self._backup_alt_m = 0.0
        self._backup_radius_m = 0.0
        self._recovery_until_ns: int | None = None

    @property
    def present(self) -> bool:
        """A fence is configured (SYS_STATUS 'present'), enabled or not."""
        return bool(int(self.params["FENCE_TYPE"]) & (_SIMULATED | FenceType.ALT_MIN))

    @property
    def enabled(self) -> bool:
        return bool(self.params["FENCE_ENABLE"]) and bool(self.types)

    @property
    def types(self) -> FenceType:
        """The fences in force now (none while FENCE_ENABLE is 0)."""
        if not self.params["FENCE_ENABLE"]:
            return _NONE
        return FenceType(int(self.params["FENCE_TYPE"])) & _SIMULATED

    @property
    def healthy(self) -> bool:
        """SYS_STATUS GEOFENCE health: set unless an enabled fence is breached, as ArduCopter."""
        return not (self.enabled and self.breaches)

    def safe_alt_max_m(self) -> float | None:
        """The highest altitude (m above home) RTL may return at: FENCE_ALT_MAX − FENCE_MARGIN
        while the altitude fence is in force, else None."""
        if not self.types & FenceType.ALT_MAX:
            return None
        return float(self.params["FENCE_ALT_MAX"] - self.params["FENCE_MARGIN"])

    def check_target(self, pos_ned_m: tuple[float, float, float]) -> Result | None:
        """DENIED (with the reason) if a target at ``pos_ned_m`` lies outside the fence."""
        types = self.types
        alt_m = -pos_ned_m[2]
        if types & FenceType.ALT_MAX and alt_m > self.params["FENCE_ALT_MAX"]:
            return denied(f"Fence: altitude {alt_m:.0f} m above FENCE_ALT_MAX")
        if (
            types & FenceType.CIRCLE
            and math.hypot(pos_ned_m[0], pos_ned_m[1]) > (self.params["FENCE_RADIUS"])
        ):
            return denied("Fence: target outside FENCE_RADIUS")
        return None

    def manual_recovery_start(self, now_ns: int) -> bool:
        """A mode change: while a fence is breached, new breaches go unanswered for
        :data:`MANUAL_RECOVERY_S`. True when that began (ArduCopter says so)."""
        if not self.breaches:
            return False
        self._recovery_until_ns = now_ns + round(MANUAL_RECOVERY_S * 1e9)
        return True

    def check(self, pos_ned_m: list[float], now_ns: int = 0) -> Breach | None:
        """Check the vehicle's position; a :class:`Breach` when it newly left the fence (not
        during a manual recovery, which still moves the backup fences)."""
        types = self.types
        if not types:  # no fence in force (FENCE_ENABLE 0, the default): nothing is breached
            self.breaches = _NONE
            return None
        new = FenceType(0)
        distance_m = 0.0
        alt_m = -pos_ned_m[2]
        alt_max = self.params["FENCE_ALT_MAX"]
        if types & FenceType.ALT_MAX and alt_m >= alt_max:
            if not self.breaches & FenceType.ALT_MAX or alt_m >= self._backup_alt_m:
                new |= FenceType.ALT_MAX
                self._backup_alt_m = alt_m + BACKUP_DISTANCE_M
                distance_m = alt_m - alt_max
        else:
            self.breaches &= ~FenceType.ALT_MAX
        radius_m = math.hypot(pos_ned_m[0], pos_ned_m[1])
        fence_radius = self.params["FENCE_RADIUS"]
        if types & FenceType.CIRCLE and radius_m >= fence_radius:
            if not self.breaches & FenceType.CIRCLE or radius_m >= self._backup_radius_m:
                new |= FenceType.CIRCLE
                self._backup_radius_m = radius_m + BACKUP_DISTANCE_M
                distance_m = max(distance_m, radius_m - fence_radius)
        else:
            self.breaches &= ~FenceType.CIRCLE
        if not new:
            return None
        self.breaches |= new
        if self._recovery_until_ns is not None:
            if now_ns < self._recovery_until_ns:
                return None
            self._recovery_until_ns = None
        mode = _ACTION_MODES.get(int(self.params["FENCE_ACTION"]))
        if mode is not None and distance_m > GIVE_UP_DISTANCE_M:
            mode = Mode.LAND
        return Breach(new, distance_m, mode)
