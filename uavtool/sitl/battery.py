"""The simulated battery: a 3S LiPo drained by the power the motors need for their thrust.

The current is the airframe's watts per newton of thrust (its hover power over its weight, as
ArduPilot's SITL reckons it) times the thrust, over the battery's voltage, plus what the
avionics draw: a vehicle that leans into the wind, climbs or carries more thrust draws more.
BATT_CAPACITY (mAh) and SIM_BATT_VOLTAGE (V, full) come from the parameter table; the
voltage falls linearly with the charge used, from full to 78.6 % of it when empty.
"""

from __future__ import annotations

from uavtool.sitl.params import ParamStore

IDLE_CURRENT_A = 0.3
"""What the avionics draw, motors or not."""


class Battery:
    """Charge and energy used so far, the current of the last step, and what the battery
    reports from them."""

    def __init__(self, params: ParamStore) -> None:
        self.params = params
        self.used_mah = 0.0
        self.used_wh = 0.0
        self.current_a = IDLE_CURRENT_A
        """Amperes drawn in the last :meth:`drain`."""

    def voltage(self) -> float:
        full = self.params["SIM_BATT_VOLTAGE"]
        capacity = max(self.params["BATT_CAPACITY"], 1.0)
        remaining = max(0.0, 1.0 - self.used_mah / capacity)
        return full * (0.786 + 0.214 * remaining)  # 3S: 12.6 V full … 9.9 V empty

    def remaining_pct(self) -> int:
        capacity = max(self.params["BATT_CAPACITY"], 1.0)
        return max(0, min(100, round(100.0 * (1.0 - self.used_mah / capacity))))

    def drain(self, *, motor_power_w: float, dt_s: float) -> None:
        """Draw ``motor_power_w`` for the motors, and the avionics' current, for ``dt_s``."""
        volts = self.voltage()
        amps = IDLE_CURRENT_A + motor_power_w / (volts if volts > 0.1 else 0.1)
        self.current_a = amps
        self.used_mah += amps * dt_s * (1000.0 / 3600.0)
        self.used_wh += amps * volts * dt_s / 3600.0
