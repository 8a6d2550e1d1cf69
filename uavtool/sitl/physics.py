"""Multicopter dynamics with an ArduCopter-like position controller, stepped by sim time.

Pure and deterministic: the state advances only through ``Multicopter.step(dt_s)``; wind
gusts come from a ``random.Random`` seeded by the caller. Frames: NED metres relative to
home, yaw in degrees clockwise from north.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from uavtool.geo import wrap_180

GRAVITY_MSS = 9.80665


@dataclass(slots=True)
class Limits:
    """Controller limits in SI units (converted from ArduCopter's cm-based parameters)."""

    speed_xy_ms: float = 10.0
    speed_up_ms: float = 2.5
    speed_dn_ms: float = 1.5
    accel_xy_mss: float = 2.5
    accel_z_mss: float = 1.0
    yaw_rate_dps: float = 60.0
    lean_max_deg: float = 30.0


@dataclass(slots=True)
class Target:
    """What the controller is asked to do.

    Exactly one of ``pos_ned_m`` (fly to and hold) or ``vel_ned_ms`` (hold a velocity)
    is used; with neither the vehicle brakes to a stop and holds where it stopped.
    ``yaw_deg`` None holds the current heading.
    """

    pos_ned_m: tuple[float, float, float] | None = None
    vel_ned_ms: tuple[float, float, float] | None = None
    yaw_deg: float | None = None
    yaw_rate_dps: float | None = None


@dataclass(frozen=True, slots=True)
class Touchdown:
    """How a step met the ground after being in the air: the velocity (m/s, NED) before ground
    contact stopped it, and the greatest height (m above home) since it left the ground."""

    vel_ned_ms: tuple[float, float, float]
    peak_up_m: float


@dataclass(slots=True)
class State:
    pos_ned_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    vel_ned_ms: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    accel_ned_mss: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    yaw_deg: float = 0.0
    yaw_rate_dps: float = 0.0
    roll_deg: float = 0.0
    pitch_deg: float = 0.0
    on_ground: bool = True


_CALM = [0.0, 0.0, 0.0]


def sqrt_controller(error: float, p_gain: float, accel_max: float) -> float:
    """ArduPilot's sqrt controller: linear near zero, constant-deceleration far away."""
    linear_dist = accel_max / (p_gain * p_gain)
    if abs(error) <= linear_dist:
        return p_gain * error
    v = math.sqrt(2.0 * accel_max * (abs(error) - linear_dist / 2.0))
    return v if error > 0 else -v


class Multicopter:
    """A point-mass multicopter flown by a cascaded position → velocity → acceleration loop."""

    POS_P = 1.0  # 1/s
    VEL_TAU_S = 0.25  # velocity loop time constant
    DRAG_PER_S = 0.15  # linear air drag coefficient

    def __init__(self, *, yaw_deg: float = 0.0, rng: random.Random | None = None) -> None:
        self.state = State(yaw_deg=yaw_deg)
        self.limits = Limits()
        self.target = Target()
        self.wind_ned_ms = (0.0, 0.0, 0.0)
        self.turbulence_ms = 0.0
        self._gust = [0.0, 0.0, 0.0]
        self._rng = rng or random.Random(0)
        self._hold: tuple[float, float, float] | None = None
        self.motors_on = False
        self.touchdown: Touchdown | None = None
        """How the last step met the ground; None when it did not (or was already on it)."""
        self._peak_up_m = 0.0  # greatest height since the vehicle last left the ground

    def set_target(self, target: Target) -> None:
        self.target = target
        self._hold = None

    def step(self, dt_s: float) -> None:
        s = self.state
        self.touchdown = None
        if not self.motors_on:
            self._settle_on_ground(dt_s)
            return
        vel_des = self._desired_velocity()
        lim = self.limits
        # Acceleration needed to reach the desired velocity, limited like ArduCopter.
        ax = (vel_des[0] - s.vel_ned_ms[0]) / self.VEL_TAU_S
        ay = (vel_des[1] - s.vel_ned_ms[1]) / self.VEL_TAU_S
        az = (vel_des[2] - s.vel_ned_ms[2]) / self.VEL_TAU_S
        a_xy = math.hypot(ax, ay)
        if a_xy > lim.accel_xy_mss:
            k = lim.accel_xy_mss / a_xy
            ax, ay = ax * k, ay * k
        az = max(-lim.accel_z_mss * 2.5, min(lim.accel_z_mss * 2.5, az))
        self._update_gust(dt_s)
        acc, vel, pos, gust = s.accel_ned_mss, s.vel_ned_ms, s.pos_ned_m, self._gust
        airborne = pos[2] < 0.0
        # each axis as a loop over them would, unrolled (every step of every flight)
        acc[0], acc[1], acc[2] = ax, ay, az
        vel[0] += ax * dt_s
        vel[1] += ay * dt_s
        vel[2] += az * dt_s
        pos[0] += (vel[0] + gust[0]) * dt_s
        pos[1] += (vel[1] + gust[1]) * dt_s
        pos[2] += (vel[2] + gust[2]) * dt_s
        self._update_attitude(ax, ay)
        self._update_yaw(dt_s)
        if s.pos_ned_m[2] >= 0.0:
            if airborne:
                self._touch_down()
            s.pos_ned_m[2] = 0.0
            s.vel_ned_ms[2] = min(s.vel_ned_ms[2], 0.0)
            s.on_ground = vel_des[2] >= 0.0
            if s.on_ground:
                s.vel_ned_ms[0] = s.vel_ned_ms[1] = 0.0
        else:
            s.on_ground = False
            if -s.pos_ned_m[2] > self._peak_up_m:  # noqa: PLR1730 (every step: no max() call)
                self._peak_up_m = -s.pos_ned_m[2]

    def _touch_down(self) -> None:
        v = self.state.vel_ned_ms
        self.touchdown = Touchdown((v[0], v[1], v[2]), self._peak_up_m)
        self._peak_up_m = 0.0

    def _desired_velocity(self) -> tuple[float, float, float]:
        s, t, lim = self.state, self.target, self.limits
        if t.vel_ned_ms is not None:
            vx, vy, vz = t.vel_ned_ms
            v_xy = math.hypot(vx, vy)
            if v_xy > lim.speed_xy_ms:
                vx, vy = vx * lim.speed_xy_ms / v_xy, vy * lim.speed_xy_ms / v_xy
            return vx, vy, max(-lim.speed_up_ms, min(lim.speed_dn_ms, vz))
        goal = t.pos_ned_m
        if goal is None:
            if self._hold is None:
                self._hold = self._stopping_point()
            goal = self._hold
        en = goal[0] - s.pos_ned_m[0]
        ee = goal[1] - s.pos_ned_m[1]
        ed = goal[2] - s.pos_ned_m[2]
        dist = math.hypot(en, ee)
        vx = vy = 0.0
        if dist > 1e-9:
            speed = min(sqrt_controller(dist, self.POS_P, lim.accel_xy_mss), lim.speed_xy_ms)
            vx, vy = en / dist * speed, ee / dist * speed
        vz = sqrt_controller(ed, self.POS_P, lim.accel_z_mss)
        return vx, vy, max(-lim.speed_up_ms, min(lim.speed_dn_ms, vz))

    def _stopping_point(self) -> tuple[float, float, float]:
        s, lim = self.state, self.limits
        point = []
        for i, acc in ((0, lim.accel_xy_mss), (1, lim.accel_xy_mss), (2, lim.accel_z_mss)):
            v = s.vel_ned_ms[i]
            point.append(s.pos_ned_m[i] + v * abs(v) / (2.0 * acc))
        return (point[0], point[1], min(point[2], 0.0))

    def _update_gust(self, dt_s: float) -> None:
        if self.turbulence_ms <= 0.0:
            if self._gust != _CALM:
                self._gust = [0.0, 0.0, 0.0]
            return
        # Ornstein-Uhlenbeck gusts with a 2 s correlation time.
        decay = math.exp(-dt_s / 2.0)
        sigma = self.turbulence_ms * math.sqrt(1.0 - decay * decay)
        self._gust = [g * decay + self._rng.gauss(0.0, sigma) for g in self._gust]
        self._gust[2] *= 0.3

    def _update_attitude(self, ax: float, ay: float) -> None:
        s = self.state
        # Thrust must supply the commanded acceleration plus the drag of the relative wind.
        wind = self.wind_ned_ms
        fx = ax - self.DRAG_PER_S * (wind[0] - s.vel_ned_ms[0])
        fy = ay - self.DRAG_PER_S * (wind[1] - s.vel_ned_ms[1])
        yaw = math.radians(s.yaw_deg)
        cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
        forward = fx * cos_yaw + fy * sin_yaw
        right = -fx * sin_yaw + fy * cos_yaw
        lean = self.limits.lean_max_deg
        s.pitch_deg = max(-lean, min(lean, -math.degrees(math.atan2(forward, GRAVITY_MSS))))
        s.roll_deg = max(-lean, min(lean, math.degrees(math.atan2(right, GRAVITY_MSS))))

    def _update_yaw(self, dt_s: float) -> None:
        s, t = self.state, self.target
        if t.yaw_deg is None:
            s.yaw_rate_dps = 0.0
            return
        rate = min(t.yaw_rate_dps or self.limits.yaw_rate_dps, self.limits.yaw_rate_dps)
        err = wrap_180(t.yaw_deg - s.yaw_deg)
        step = max(-rate * dt_s, min(rate * dt_s, err))
        s.yaw_rate_dps = step / dt_s
        s.yaw_deg = (s.yaw_deg + step) % 360.0

    def _settle_on_ground(self, dt_s: float) -> None:
        s = self.state
        if s.pos_ned_m[2] < 0.0:  # motors off in the air: fall
            s.vel_ned_ms[2] += GRAVITY_MSS * dt_s
            s.pos_ned_m[2] = min(0.0, s.pos_ned_m[2] + s.vel_ned_ms[2] * dt_s)
            s.on_ground = s.pos_ned_m[2] >= 0.0
            if s.on_ground:
                self._touch_down()
        else:
            s.on_ground = True
        if s.on_ground:
            s.vel_ned_ms[:] = [0.0, 0.0, 0.0]
            s.accel_ned_mss[:] = [0.0, 0.0, 0.0]
            s.roll_deg = s.pitch_deg = s.yaw_rate_dps = 0.0
