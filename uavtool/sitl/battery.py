"""The simulated battery: a 4S LiPo drained by the current the flight draws.

BATT_CAPACITY (mAh) and SIM_BATT_VOLTAGE (V, full) come from the parameter table; the
voltage falls linearly with the charge used, from full to 78.6 % of it when empty.
"""

from __future__ import annotations

import math

from uavtool.sitl.params import ParamStore
from uavtool.sitl.physics import State


class Battery:
    """Charge used so far, and what the battery reports from it."""

    def __init__(self, params: ParamStore) -> None:
        self.params = params
        self.used_mah = 0.0

    def voltage(self) -> float:
        full = self.params["SIM_BATT_VOLTAGE"]
        capacity = max(self.params["BATT_CAPACITY"], 1.0)
        remaining = max(0.0, 1.0 - self.used_mah / capacity)
        return full * (0.786 + 0.214 * remaining)  # 4S: 16.8 V full … 13.2 V empty

    def remaining_pct(self) -> int:
        capacity = max(self.params["BATT_CAPACITY"], 1.0)
        return max(0, min(100, round(100.0 * (1.0 - self.used_mah / capacity))))

    @staticmethod
    def current_a(*, armed: bool, state: State) -> float:
        """Amperes drawn: idle when disarmed, more to accelerate and to climb."""
        if not armed:
            return 0.3
        return (
            12.0
            + 3.0 * math.hypot(state.accel_ned_mss[0], state.accel_ned_mss[1])
            + 4.0 * max(0.0, -state.vel_ned_ms[2])
        )

    def drain(self, current_a: float, dt_s: float) -> None:
        self.used_mah += current_a * dt_s * 1000.0 / 3600.0
