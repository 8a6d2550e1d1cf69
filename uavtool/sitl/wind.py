"""The air the vehicle flies in: a steady wind that weakens near the ground, and seeded
turbulence, with ArduPilot's SITL parameters and meanings.

- ``SIM_WIND_SPD`` (m/s) blowing from ``SIM_WIND_DIR`` (degrees, true), tilted up by
  ``SIM_WIND_DIR_Z`` degrees (an updraft).
- ``SIM_WIND_T`` how the wind grows with height above the ground: 0, as the square root of
  height up to ``SIM_WIND_T_ALT`` (full speed above it; ArduPilot's default, 60 m); 1, the same
  at every height; 2, linearly, by ``SIM_WIND_T_COEF`` per metre from ``SIM_WIND_T_ALT``.
- ``SIM_WIND_TC`` (s): a changed speed or direction takes effect through a low-pass filter of
  this time constant, as ArduPilot's does.
- ``SIM_WIND_TURB`` (m/s): turbulence, only in the air. ArduPilot's SITL makes it at its
  1200 Hz physics rate from a filtered random speed (standard deviation SIM_WIND_TURB, time
  constant 0.041 s) blowing from a new random direction at every step, plus a filtered
  vertical speed of the same size. Seen over one of our steps (``dt``), its horizontal part
  averages to white noise of standard deviation SIM_WIND_TURB / √(2400 dt) per axis, and its
  vertical part stays a first-order process of 0.041 s: that is what :class:`Wind` draws, so
  that the same SIM_WIND_TURB shakes the built-in vehicle as it shakes ArduCopter's.

Only the air moves: the vehicle feels wind and gusts through its drag, never as a push on its
position.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

ARDUPILOT_SIM_RATE_HZ = 1200.0
"""ArduPilot's SITL physics rate (its SIM_RATE_HZ on the SITL board), at which it draws its
turbulence."""
TURBULENCE_TC_S = -1.0 / (ARDUPILOT_SIM_RATE_HZ * math.log(0.98))
"""The time constant of ArduPilot's turbulence filter (0.98 a step at 1200 Hz): 0.041 s."""
_SQRT, _NO_LIMIT, _LINEAR = 0, 1, 2


@dataclass(frozen=True, slots=True)
class WindParams:
    """The SIM_WIND_* parameters (ArduPilot's units)."""

    speed_ms: float = 0.0
    from_deg: float = 0.0
    up_deg: float = 0.0
    turbulence_ms: float = 0.0
    change_tc_s: float = 5.0
    profile: int = _SQRT
    profile_alt_m: float = 60.0
    profile_coef: float = 0.01


class Wind:
    """The air's velocity at the vehicle (NED, m/s: where the air goes), step by step.

    Seeded by ``rng`` alone: the same seed and steps give the same gusts."""

    def __init__(self, rng: random.Random, params: WindParams | None = None) -> None:
        self._rng = rng
        self.params = params or WindParams()
        self._speed_ms = self.params.speed_ms  # the filtered, active values
        self._from_deg = self.params.from_deg
        self._up_deg = self.params.up_deg
        self._gust_d = 0.0
        self.ned_ms = (0.0, 0.0, 0.0)
        """The air's velocity after the last :meth:`step`."""
        self._dt_s = 0.0
        self._gust_keep = self._gust_new = self._gust_h = 0.0
        self._steady_key: tuple[float, float, float, float] | None = None
        self._steady = (0.0, 0.0, 0.0)

    def set_params(self, params: WindParams) -> None:
        """New parameters: the speed and direction move to them with SIM_WIND_TC."""
        self.params = params

    def step(self, height_m: float, *, airborne: bool, dt_s: float) -> tuple[float, float, float]:
        """Advance the air by ``dt_s`` at ``height_m`` above the ground; return its velocity."""
        p = self.params
        if self._speed_ms != p.speed_ms or self._from_deg != p.from_deg or self._up_deg != p.up_deg:
            self._slew(dt_s)
        n, e, d = self._steady_at(height_m)
        if p.turbulence_ms > 0.0 and airborne:
            if dt_s != self._dt_s:
                self._dt_s = dt_s
                self._gust_keep = math.exp(-dt_s / TURBULENCE_TC_S)
                self._gust_new = math.sqrt(1.0 - self._gust_keep * self._gust_keep)
                self._gust_h = 1.0 / math.sqrt(2.0 * ARDUPILOT_SIM_RATE_HZ * dt_s)
            gauss = self._rng.gauss
            turb = p.turbulence_ms
            self._gust_d = self._gust_d * self._gust_keep + turb * self._gust_new * gauss(0.0, 1.0)
            h = turb * self._gust_h
            n += h * gauss(0.0, 1.0)
            e += h * gauss(0.0, 1.0)
            d += self._gust_d
        self.ned_ms = (n, e, d)
        return self.ned_ms

    def _slew(self, dt_s: float) -> None:
        p = self.params
        alpha = dt_s / (dt_s + max(p.change_tc_s, 0.1) / (2.0 * math.pi))
        self._speed_ms += (p.speed_ms - self._speed_ms) * alpha
        turn = (p.from_deg - self._from_deg + 180.0) % 360.0 - 180.0
        self._from_deg = (self._from_deg + turn * alpha) % 360.0
        self._up_deg += (p.up_deg - self._up_deg) * alpha
        # Close enough to stop filtering: exactly the set values from here on.
        if (
            abs(p.speed_ms - self._speed_ms) < 1e-4
            and abs(turn) * (1.0 - alpha) < 1e-4
            and abs(p.up_deg - self._up_deg) < 1e-4
        ):
            self._speed_ms, self._from_deg, self._up_deg = p.speed_ms, p.from_deg, p.up_deg

    def _steady_at(self, height_m: float) -> tuple[float, float, float]:
        p = self.params
        speed = self._speed_ms
        if speed <= 0.0:
            return (0.0, 0.0, 0.0)
        if p.profile == _SQRT:
            if p.profile_alt_m > 0.0 and height_m < p.profile_alt_m:
                speed *= math.sqrt(max(height_m, 0.0) / p.profile_alt_m)
        elif p.profile == _LINEAR:
            speed = max(speed + (height_m - p.profile_alt_m) * p.profile_coef, 0.0)
        key = (speed, self._from_deg, self._up_deg, 0.0)
        if key != self._steady_key:
            self._steady_key = key
            frm, up = math.radians(self._from_deg), math.radians(self._up_deg)
            flat = speed * math.cos(up)
            # It blows *from* the direction: the air moves the other way.
            self._steady = (-flat * math.cos(frm), -flat * math.sin(frm), -speed * math.sin(up))
        return self._steady
