"""The built-in vehicle's flight: ArduCopter's controllers (:mod:`~uavtool.sitl.control`) flying
an airframe (:mod:`~uavtool.sitl.frame`) through the air (:mod:`~uavtool.sitl.wind`), as
ArduPilot's SITL builds a multicopter: controllers -> thrust and attitude -> forces -> motion.

Each step (``Multicopter.step(dt_s)``):

1. the air moves (the steady wind at this height, turbulence in the air);
2. the controllers turn the target into a lean of the thrust vector and a thrust command;
3. the lean and the heading move toward theirs as ArduCopter's attitude controller shapes
   them, the motors' thrust toward its command with their time constant;
4. the forces: thrust along the tilted axis (less what air flowing into the propellers takes),
   drag of the airspeed (wind minus velocity) across and along the rotor plane, gravity;
5. motion, and the ground: a vehicle on the ground stays where it is (no sliding, level)
   until its thrust lifts it; on the ground with the throttle at its lower limit for a second
   it is landed (ArduCopter's land detector).

Pure and deterministic: the state advances only through ``step``; turbulence comes from the
``random.Random`` the caller seeds. Frames: NED metres relative to home, yaw in degrees
clockwise from north.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from uavtool.sitl.attitude import AttitudeShaper
from uavtool.sitl.control import (
    GRAVITY_MSS,
    IDLE,
    Command,
    Gains,
    Limits,
    PositionController,
    Target,
)
from uavtool.sitl.frame import Airframe, Frame, air_density_kgm3, airframe
from uavtool.sitl.wind import Wind

__all__ = ["GRAVITY_MSS", "Limits", "Multicopter", "State", "Target", "Touchdown"]

LAND_DETECTOR_TRIGGER_S = 1.0
"""The throttle at its lower limit on the ground this long means landed (ArduCopter's
LAND_DETECTOR_TRIGGER_SEC)."""
_LOWER_LIMIT = 0.05
"""Thrust below this share of the weight counts as the throttle's lower limit."""
_DEG = math.pi / 180.0


@dataclass(frozen=True, slots=True)
class Touchdown:
    """How a step met the ground after being in the air: the velocity (m/s, NED) before ground
    contact stopped it, and the greatest height (m above home) since it left the ground."""

    vel_ned_ms: tuple[float, float, float]
    peak_up_m: float


@dataclass(slots=True)
class State:
    """The vehicle's true state. ``lean_ne`` is the horizontal part of the unit thrust
    direction (north, east): the tilt, whatever the heading."""

    pos_ned_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    vel_ned_ms: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    accel_ned_mss: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    yaw_deg: float = 0.0
    yaw_rate_dps: float = 0.0
    lean_ne: list[float] = field(default_factory=lambda: [0.0, 0.0])
    thrust_n: float = 0.0
    thrust_max_n: float = 1.0
    on_ground: bool = True
    """Touching the ground (the ground carries it)."""
    landed: bool = True
    """ArduCopter's land detector: on the ground with the throttle at its lower limit."""

    def _forward_right(self) -> tuple[float, float]:
        yaw = self.yaw_deg * _DEG
        c, s = math.cos(yaw), math.sin(yaw)
        ln, le = self.lean_ne
        return ln * c + le * s, -ln * s + le * c

    @property
    def roll_deg(self) -> float:
        """Roll of the body (right side down positive), from the lean and the heading."""
        _, right = self._forward_right()
        return math.degrees(math.asin(max(-1.0, min(1.0, right))))

    @property
    def pitch_deg(self) -> float:
        """Pitch of the body (nose up positive), from the lean and the heading."""
        forward, right = self._forward_right()
        across = math.sqrt(max(1.0 - right * right, 1e-12))
        return -math.degrees(math.asin(max(-1.0, min(1.0, forward / across))))

    @property
    def throttle(self) -> float:
        """The thrust as a share of the most the motors give (0-1)."""
        return self.thrust_n / self.thrust_max_n


class Multicopter:
    """A multicopter flown by ArduCopter's cascaded controllers through forces."""

    def __init__(
        self,
        *,
        yaw_deg: float = 0.0,
        rng: random.Random | None = None,
        frame: Frame | None = None,
        home_alt_amsl_m: float = 0.0,
    ) -> None:
        self.frame = frame or Frame()
        self.body: Airframe = airframe(self.frame, density_kgm3=air_density_kgm3(home_alt_amsl_m))
        self.state = State(yaw_deg=yaw_deg, thrust_max_n=self.body.thrust_max_n)
        self.control = PositionController(
            mass_kg=self.body.mass_kg, thrust_max_n=self.body.thrust_max_n
        )
        self.limits: Limits = self.control.limits
        self.gains: Gains = self.control.gains
        self.attitude = AttitudeShaper()
        self.air = Wind(rng or random.Random(0))
        self.motors_on = False
        self.touchdown: Touchdown | None = None
        """How the last step met the ground; None when it did not (or was already on it)."""
        self._peak_up_m = 0.0  # greatest height since the vehicle last left the ground
        self._lower_limit_s = 0.0  # how long the throttle has been at its lower limit
        self._cmd = IDLE
        self._dt_s = 0.0
        self._motor_keep = 0.0

    # ------------------------------------------------------------------ commands
    @property
    def target(self) -> Target:
        return self.control.target

    @target.setter
    def target(self, target: Target) -> None:
        self.control.target = target

    def set_target(self, target: Target) -> None:
        """A new target (the brake's hold point, if any, is forgotten)."""
        self.control.set_target(target)

    def arm(self) -> None:
        """Motors armed: still for ArduCopter's arming delay, then at ground idle."""
        self.motors_on = True
        self.control.arm(in_air=not self.state.on_ground)

    def disarm(self) -> None:
        self.motors_on = False
        self.control.disarm()

    def stopping_point(self) -> tuple[float, float, float]:
        """Where the vehicle would come to rest braking now (NED m): ArduCopter starts RTL and
        its brake from here."""
        return self.control.stopping_point(self.state.pos_ned_m, self.state.vel_ned_ms)

    # ------------------------------------------------------------------ the step
    def step(self, dt_s: float) -> None:
        s = self.state
        self.touchdown = None
        if not self.motors_on and s.on_ground and s.thrust_n < 1e-3:
            s.thrust_n = 0.0
            s.vel_ned_ms[0] = s.vel_ned_ms[1] = s.vel_ned_ms[2] = 0.0
            s.accel_ned_mss[0] = s.accel_ned_mss[1] = s.accel_ned_mss[2] = 0.0
            s.lean_ne[0] = s.lean_ne[1] = s.yaw_rate_dps = 0.0
            s.landed = True
            return
        if dt_s != self._dt_s:
            self._dt_s = dt_s
            tc = self.body.motor_time_constant_s
            self._motor_keep = math.exp(-dt_s / tc) if tc > 0.0 else 0.0
        air = self.air.step(-s.pos_ned_m[2], airborne=not s.on_ground, dt_s=dt_s)
        control = self.control
        if self.motors_on:
            cmd = self._cmd = control.update(
                s.pos_ned_m,
                s.vel_ned_ms,
                s.accel_ned_mss,
                s.lean_ne,
                on_ground=s.on_ground,
                landed=s.landed,
                thrust_n=s.thrust_n,
                dt_s=dt_s,
            )
        else:
            cmd = self._cmd = IDLE
        if s.on_ground and not control.flying:
            s.lean_ne[0] = s.lean_ne[1] = s.yaw_rate_dps = 0.0
            self.attitude.stop()
        else:
            self.attitude.lean(s.lean_ne, cmd, control.gains, dt_s)
            s.yaw_deg, s.yaw_rate_dps = self.attitude.yaw(
                s.yaw_deg, s.yaw_rate_dps, control.target, control.limits, control.gains, dt_s
            )
        # the motors follow their command with a lag
        s.thrust_n = cmd.thrust_n + (s.thrust_n - cmd.thrust_n) * self._motor_keep
        self._move(air, dt_s)
        if not s.landed:
            self._detect_landing(dt_s)

    @property
    def command(self) -> Command:
        """What the controllers asked of the airframe in the last step."""
        return self._cmd

    # ------------------------------------------------------------------ forces and motion
    def _move(self, air: tuple[float, float, float], dt_s: float) -> None:
        s, body = self.state, self.body
        pos, vel, acc = s.pos_ned_m, s.vel_ned_ms, s.accel_ned_mss
        ln, le = s.lean_ne
        up = 1.0 - ln * ln - le * le
        ld = -math.sqrt(up) if up > 0.0 else 0.0  # the thrust direction (NED, unit)
        thrust = s.thrust_n
        # Air relative to the vehicle, along the thrust axis and across the rotor plane.
        rn, re, rd = vel[0] - air[0], vel[1] - air[1], vel[2] - air[2]
        axial = rn * ln + re * le + rd * ld  # > 0: the vehicle moves along its thrust
        pn, pe, pd = rn - axial * ln, re - axial * le, rd - axial * ld
        across = math.sqrt(pn * pn + pe * pe + pd * pd)
        mom = body.momentum_drag * math.sqrt(thrust) if thrust > 0.0 else 0.0
        quad = body.drag_area_n_per_ms2
        k_across = quad * across + mom
        if axial > 0.0:  # air flowing into the propellers takes some of their thrust
            thrust -= body.inflow_area_n_per_ms2 * axial * axial
            thrust = max(thrust, 0.0)
            f_axial = thrust - (quad * axial + mom) * axial
        else:
            f_axial = thrust - (mom - quad * axial) * axial
        inv_m = 1.0 / body.mass_kg
        an = (f_axial * ln - k_across * pn) * inv_m
        ae = (f_axial * le - k_across * pe) * inv_m
        ad = (f_axial * ld - k_across * pd) * inv_m + GRAVITY_MSS
        if s.on_ground and ad > 0.0:
            ad = 0.0  # the ground carries it
        acc[0], acc[1], acc[2] = an, ae, ad
        vel[0] += an * dt_s
        vel[1] += ae * dt_s
        vel[2] += ad * dt_s
        pos[0] += vel[0] * dt_s
        pos[1] += vel[1] * dt_s
        pos[2] += vel[2] * dt_s
        if pos[2] >= 0.0:
            if not s.on_ground:
                self.touchdown = Touchdown((vel[0], vel[1], vel[2]), self._peak_up_m)
                self._peak_up_m = 0.0
            # On the ground: it does not slide, and stands level (ArduPilot's SITL, too).
            pos[2] = 0.0
            vel[0] = vel[1] = 0.0
            vel[2] = min(vel[2], 0.0)
            acc[0] = acc[1] = 0.0
            s.lean_ne[0] = s.lean_ne[1] = 0.0
            self.attitude.stop()
            s.on_ground = True
        else:
            s.on_ground = False
            s.landed = False
            if -pos[2] > self._peak_up_m:  # noqa: PLR1730 (every step: no max() call)
                self._peak_up_m = -pos[2]

    def _detect_landing(self, dt_s: float) -> None:
        s = self.state
        if s.on_ground and s.thrust_n <= _LOWER_LIMIT * self.body.weight_n:
            self._lower_limit_s += dt_s
            if self._lower_limit_s >= LAND_DETECTOR_TRIGGER_S or not self.motors_on:
                s.landed = True
                self._lower_limit_s = 0.0
                self.control.landed(s.pos_ned_m)
        else:
            self._lower_limit_s = 0.0
