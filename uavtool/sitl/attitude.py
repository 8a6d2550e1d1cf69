"""ArduCopter's attitude controller's input shaping, as the built-in vehicle flies it: the lean
of the thrust vector and the heading move toward their targets along the square-root curve of
ATC_INPUT_TC, their rates changing no faster than ATC_ACCEL_R_MAX/P_MAX and ATC_ACCEL_Y_MAX
allow, the heading's rate within ATC_SLEW_YAW (or what a CONDITION_YAW asked for).
ArduCopter's rate loops track that shaped attitude closely: the built-in vehicle's attitude is
the shaped one.
"""

from __future__ import annotations

import math

from uavtool.geo import wrap_180
from uavtool.sitl.control import Command, Gains, Limits, Target
from uavtool.sitl.shaping import shape_rate, sqrt_controller

_DEG = math.pi / 180.0


class AttitudeShaper:
    """The lean's rates (north, east; rad/s) between steps; the heading's rate is the
    vehicle's state."""

    def __init__(self) -> None:
        self.lean_rate = [0.0, 0.0]

    def stop(self) -> None:
        self.lean_rate[0] = self.lean_rate[1] = 0.0

    def lean(self, lean: list[float], cmd: Command, gains: Gains, dt_s: float) -> None:
        rate = self.lean_rate
        en, ee = cmd.lean_n - lean[0], cmd.lean_e - lean[1]
        if en == ee == rate[0] == rate[1] == 0.0:
            return
        p = 1.0 / max(gains.input_tc_s, 0.01)
        acc = gains.accel_rp_max_dss * _DEG
        step = acc * dt_s
        rate[0] = shape_rate(rate[0], sqrt_controller(en, p, acc), step)
        rate[1] = shape_rate(rate[1], sqrt_controller(ee, p, acc), step)
        if -1e-12 < en < 1e-12 and -1e-12 < ee < 1e-12 and abs(rate[0]) + abs(rate[1]) < step:
            lean[0], lean[1] = cmd.lean_n, cmd.lean_e
            rate[0] = rate[1] = 0.0
            return
        lean[0] += rate[0] * dt_s
        lean[1] += rate[1] * dt_s
        across = lean[0] * lean[0] + lean[1] * lean[1]
        if across > 0.9:  # never past 72°: the thrust must still carry some weight
            k = math.sqrt(0.9 / across)
            lean[0] *= k
            lean[1] *= k

    @staticmethod
    def yaw(
        yaw_deg: float,
        rate_dps: float,
        target: Target,
        limits: Limits,
        gains: Gains,
        dt_s: float,
    ) -> tuple[float, float]:
        """The heading and its rate after ``dt_s``, turning toward ``target.yaw_deg``."""
        if target.yaw_deg is None:
            return yaw_deg, 0.0
        err = wrap_180(target.yaw_deg - yaw_deg)
        if err == 0.0 and rate_dps == 0.0:
            return yaw_deg, 0.0
        limit = min(target.yaw_rate_dps or limits.yaw_rate_dps, limits.yaw_rate_dps)
        acc = gains.accel_y_max_dss
        want = sqrt_controller(err, 1.0 / max(gains.input_tc_s, 0.01), acc)
        want = -limit if want < -limit else (limit if want > limit else want)
        rate = shape_rate(rate_dps, want, acc * dt_s)
        if abs(err) < 1e-6 and abs(rate) < acc * dt_s:  # there: stop exactly
            return target.yaw_deg % 360.0, 0.0
        return (yaw_deg + rate * dt_s) % 360.0, rate
