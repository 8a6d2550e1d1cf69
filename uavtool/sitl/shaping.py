"""ArduPilot's command shaping, as plain functions: how its controllers turn a distance into a
speed and a speed into an acceleration without overshooting the limits they are given
(ArduPilot's ``AP_Math/control.cpp`` does the same; this is our own code after its published
behaviour). Units are whatever the caller's are: metres and seconds in the position
controller, radians in the attitude controller, degrees for the heading.
"""

from __future__ import annotations

import math


def sqrt_controller(error: float, p_gain: float, accel_max: float) -> float:
    """The rate that closes ``error``: proportional (``p_gain``) near zero, and far away the
    speed from which ``accel_max`` just stops at zero."""
    linear_dist = accel_max / (p_gain * p_gain)
    if -linear_dist <= error <= linear_dist:
        return p_gain * error
    v = math.sqrt(2.0 * accel_max * (abs(error) - linear_dist / 2.0))
    return v if error > 0 else -v


def sqrt_controller_accel(
    error: float, rate_cmd: float, rate: float, p_gain: float, accel_max: float
) -> float:
    """How fast :func:`sqrt_controller`'s output changes while the error closes at ``rate``:
    fed forward, it lets a follower brake as the curve asks rather than after it."""
    if rate_cmd * rate <= 0.0:
        return 0.0
    if -accel_max / (p_gain * p_gain) <= error <= accel_max / (p_gain * p_gain):
        return -p_gain * rate
    return -(accel_max / abs(rate_cmd)) * rate


def stopping_distance(speed: float, p_gain: float, accel_max: float) -> float:
    """The error at which :func:`sqrt_controller` asks for ``speed`` (its inverse): how far a
    vehicle at that speed goes before the controller has it at rest."""
    linear_dist = accel_max / (p_gain * p_gain)
    if speed <= p_gain * linear_dist:
        return speed / p_gain
    return speed * speed / (2.0 * accel_max) + linear_dist / 2.0


def shape_pos_xy(
    en: float, ee: float, vn: float, ve: float, speed: float, accel: float, k_v: float
) -> tuple[float, float]:
    """The horizontal acceleration that brings a target moving at (vn, ve) to rest (en, ee)
    away: the square-root controller's velocity (gain ``k_v`` = jerk / accel), less what it
    must shed as the target closes, within ``speed``; then ``k_v`` times the velocity error,
    within ``accel``."""
    dist = math.sqrt(en * en + ee * ee)
    cn = ce = 0.0
    if dist > 0.0:
        closing = (vn * en + ve * ee) / dist
        v_cmd = sqrt_controller(dist, k_v, accel)
        v_cmd += sqrt_controller_accel(dist, v_cmd, closing, k_v, accel) / k_v
        v_cmd = -speed if v_cmd < -speed else (speed if v_cmd > speed else v_cmd)
        cn, ce = en * v_cmd / dist, ee * v_cmd / dist
    an, ae = (cn - vn) * k_v, (ce - ve) * k_v
    a = math.sqrt(an * an + ae * ae)
    if a > accel:
        an, ae = an * accel / a, ae * accel / a
    return an, ae


def shape_pos_z(
    ed: float, vd: float, up_ms: float, down_ms: float, accel: float, k_v: float
) -> float:
    """:func:`shape_pos_xy` on the vertical (NED: down positive), within the climb rate
    ``up_ms`` and the descent rate ``down_ms``."""
    v_cmd = sqrt_controller(ed, k_v, accel)
    v_cmd += sqrt_controller_accel(ed, v_cmd, vd, k_v, accel) / k_v
    v_cmd = -up_ms if v_cmd < -up_ms else (down_ms if v_cmd > down_ms else v_cmd)
    a = (v_cmd - vd) * k_v
    return -accel if a < -accel else (accel if a > accel else a)


def shape_rate(rate: float, wanted: float, step: float) -> float:
    """``rate`` moved toward ``wanted`` by at most ``step`` (an acceleration limit × dt)."""
    if wanted > rate + step:
        return rate + step
    if wanted < rate - step:
        return rate - step
    return wanted


class SCurve:
    """A rest-to-rest move of ``distance`` along a straight line, as ArduPilot's waypoint
    navigation flies a leg: the acceleration ramps at ``jerk``, holds at most ``accel``, the
    speed at most ``speed``, and the move ends at rest on the spot. Symmetric: the braking
    half mirrors the speeding-up half. ``at(t)`` gives (distance, speed, acceleration) along
    the line ``t`` seconds after the start."""

    def __init__(self, distance: float, *, speed: float, accel: float, jerk: float) -> None:
        if not (distance >= 0.0 and speed > 0.0 and accel > 0.0 and jerk > 0.0):
            raise ValueError(f"S-curve needs positive limits, got {speed}, {accel}, {jerk}")
        self.distance = distance
        self.jerk = jerk
        peak = speed
        if self._speeding_up_distance(peak, accel, jerk) * 2.0 > distance:
            # no cruise: the fastest speed from which the move still stops in time
            if distance / 2.0 <= accel**3 / jerk**2:  # too short to reach full acceleration
                peak = (distance * math.sqrt(jerk) / 2.0) ** (2.0 / 3.0)
            else:
                ramp = accel / jerk
                peak = accel / 2.0 * (-ramp + math.sqrt(ramp * ramp + 4.0 * distance / accel))
        self.peak_speed = peak
        # the speeding-up half: jerk for t_j, constant acceleration for t_a, jerk down for t_j
        if peak * jerk <= accel * accel:
            self._t_j, self._t_a = math.sqrt(peak / jerk), 0.0
        else:
            self._t_j, self._t_a = accel / jerk, peak / accel - accel / jerk
        self._t_up = 2.0 * self._t_j + self._t_a
        self._d_up = peak * self._t_up / 2.0
        cruise = distance - 2.0 * self._d_up
        self._t_cruise = cruise / peak if peak > 0.0 and cruise > 0.0 else 0.0
        self.duration = 2.0 * self._t_up + self._t_cruise

    @staticmethod
    def _speeding_up_distance(speed: float, accel: float, jerk: float) -> float:
        """How far the move goes while reaching ``speed`` from rest."""
        if speed * jerk <= accel * accel:
            return speed * math.sqrt(speed / jerk)
        return speed * (speed / accel + accel / jerk) / 2.0

    def at(self, t: float) -> tuple[float, float, float]:
        if t <= 0.0:
            return 0.0, 0.0, 0.0
        if t >= self.duration:
            return self.distance, 0.0, 0.0
        if t <= self._t_up:
            return self._up(t)
        if t <= self._t_up + self._t_cruise:
            return self._d_up + self.peak_speed * (t - self._t_up), self.peak_speed, 0.0
        s, v, a = self._up(self.duration - t)
        return self.distance - s, v, -a

    def _up(self, t: float) -> tuple[float, float, float]:
        """Distance, speed and acceleration ``t`` seconds into the speeding-up half."""
        j, t_j, t_a = self.jerk, self._t_j, self._t_a
        a_max = j * t_j
        if t <= t_j:
            return j * t**3 / 6.0, j * t * t / 2.0, j * t
        s1, v1 = j * t_j**3 / 6.0, j * t_j * t_j / 2.0
        if t <= t_j + t_a:
            u = t - t_j
            return s1 + v1 * u + a_max * u * u / 2.0, v1 + a_max * u, a_max
        s2, v2 = s1 + v1 * t_a + a_max * t_a * t_a / 2.0, v1 + a_max * t_a
        u = t - t_j - t_a
        return (
            s2 + v2 * u + a_max * u * u / 2.0 - j * u**3 / 6.0,
            v2 + a_max * u - j * u * u / 2.0,
            a_max - j * u,
        )
