"""ArduCopter's flight controllers, as the built-in vehicle runs them: what the autopilot asks of
the airframe, never what the airframe does.

- A *kinematic target* moves toward the commanded position (or at the commanded velocity)
  within the speed, acceleration and jerk limits (WPNAV_*, PSC_JERK_*): the path
  ArduCopter's position controller shapes before it flies it (:mod:`~uavtool.sitl.shaping`).
- The *position controller* follows that target: position error -> velocity (PSC_POSXY_P,
  PSC_POSZ_P, through the square-root controller), velocity error -> acceleration
  (PSC_VELXY_P and _I, PSC_VELZ_P, an integrator on the vertical) plus the target's own
  acceleration. The integrators learn what the air does (a steady wind, an updraft);
  nothing here knows the wind.
- *Acceleration -> lean and thrust*: the horizontal acceleration becomes a lean of the thrust
  vector, limited to ANGLE_MAX (a wind that needs more lean than that wins: the vehicle
  drifts, and the target waits for it); the vertical one becomes thrust, boosted by the lean.
- The attitude controller's input shaping is :mod:`~uavtool.sitl.attitude`'s.
- *Motors and ground*: ArduCopter's 2 s arming delay, the spool-up (MOT_SPOOL_TIME), the
  take-off throttle ramp (TKOFF_SLEW_TIME) until the vehicle leaves the ground, and on the
  ground the throttle wound down to its lower limit.

Units: SI, NED metres; radians inside, degrees in the targets and limits the autopilot sets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from uavtool.sitl.shaping import (
    SCurve,
    shape_pos_xy,
    shape_pos_z,
    shape_rate,
    sqrt_controller,
    stopping_distance,
)

GRAVITY_MSS = 9.80665
ARMING_DELAY_S = 2.0
"""ArduCopter keeps its motors still this long after arming (ARMING_DELAY_SEC)."""
VEL_ERROR_FILTER_HZ = 5.0
"""The horizontal velocity controller's input filter (ArduCopter's PSC_VELXY_FLTE)."""
_DEG = math.pi / 180.0


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
class Gains:
    """ArduCopter's controller gains and shaping limits (its parameters' defaults)."""

    pos_ne_p: float = 1.0  # PSC_POSXY_P, 1/s
    vel_ne_p: float = 2.0  # PSC_VELXY_P, 1/s
    vel_ne_i: float = 1.0  # PSC_VELXY_I, 1/s²
    vel_ne_imax_mss: float = 10.0  # PSC_VELXY_IMAX (m/s²)
    pos_d_p: float = 1.0  # PSC_POSZ_P, 1/s
    vel_d_p: float = 5.0  # PSC_VELZ_P, 1/s
    vel_d_i: float = 1.0  # the vertical integrator (ArduCopter's sits on the acceleration)
    jerk_xy_msss: float = 5.0  # PSC_JERK_XY, m/s³
    jerk_path_msss: float = 1.0  # WPNAV_JERK, m/s³
    jerk_z_msss: float = 5.0  # PSC_JERK_Z, m/s³
    input_tc_s: float = 0.15  # ATC_INPUT_TC
    accel_rp_max_dss: float = 1100.0  # ATC_ACCEL_R_MAX / _P_MAX, deg/s²
    accel_y_max_dss: float = 270.0  # ATC_ACCEL_Y_MAX, deg/s²
    spool_time_s: float = 0.5  # MOT_SPOOL_TIME
    takeoff_slew_s: float = 2.0  # TKOFF_SLEW_TIME


@dataclass(slots=True)
class Target:
    """What the controller is asked to do.

    Exactly one of ``pos_ned_m`` (fly to and hold) or ``vel_ned_ms`` (hold a velocity)
    is used; with neither the vehicle brakes to a stop and holds where it stopped.
    ``yaw_deg`` None holds the current heading. ``path``: a waypoint of a route (AUTO, RTL),
    which ArduCopter flies along its S-curves with the gentler WPNAV_JERK; a position target
    (GUIDED) is flown with PSC_JERK_XY.
    """

    pos_ned_m: tuple[float, float, float] | None = None
    vel_ned_ms: tuple[float, float, float] | None = None
    yaw_deg: float | None = None
    yaw_rate_dps: float | None = None
    path: bool = False


@dataclass(frozen=True, slots=True)
class Command:
    """What the controllers ask of the airframe for one step: the lean of the thrust vector
    (north and east parts of its unit direction) and the thrust, newtons."""

    lean_n: float
    lean_e: float
    thrust_n: float


IDLE = Command(0.0, 0.0, 0.0)


class PositionController:
    """ArduCopter's take-off, position and velocity control for an airframe of ``mass_kg``
    whose motors give at most ``thrust_max_n``; ``update`` reads the vehicle's true state
    (its estimate, in a simulator) and answers a :class:`Command`."""

    def __init__(self, *, mass_kg: float, thrust_max_n: float) -> None:
        self.mass_kg = mass_kg
        self.thrust_max_n = thrust_max_n
        self.limits = Limits()
        self.gains = Gains()
        self.target = Target()
        self.flying = False
        """The position controller has the vehicle (from lift-off until it is landed)."""
        self.armed_s = 0.0
        self._spool = 0.0  # 0: motors at ground idle … 1: throttle unlimited
        self._takeoff_throttle = -1.0
        self._hold: tuple[float, float, float] | None = None
        self._tp = [0.0, 0.0, 0.0]  # the kinematic target: position, velocity, acceleration
        self._tv = [0.0, 0.0, 0.0]
        self._ta = [0.0, 0.0, 0.0]
        self._i = [0.0, 0.0, 0.0]  # the velocity integrators, m/s²
        self._verr = [0.0, 0.0]  # the horizontal velocity error, filtered
        self._limit = (0.0, 0.0)  # the direction the lean was limited in, last step
        self._wind_down = 0.0  # m/s² the vertical integrator took off the thrust on the ground
        self._verr_alpha = 1.0
        self._dt_s = 0.0
        # a route's leg (Target.path): its S-curve, start, direction, and time flown along it
        self._curve: SCurve | None = None
        self._curve_from = (0.0, 0.0, 0.0)
        self._curve_dir = (0.0, 0.0, 0.0)
        self._curve_s = 0.0
        self._curve_pending = False
        self._lag = 0.0  # the position error over the leash, last step
        self.leg_done = False
        """The last route leg's S-curve has reached its end (ArduPilot's ``reached
        destination``, less the vehicle's own distance, which the caller judges)."""

    # ------------------------------------------------------------------ commands
    def set_target(self, target: Target) -> None:
        self.target = target
        self._hold = None
        self._curve = None
        self._curve_pending = target.path and target.pos_ned_m is not None
        self.leg_done = False

    def arm(self, *, in_air: bool) -> None:
        self.armed_s = 0.0
        self._spool = 0.0
        self._takeoff_throttle = -1.0
        self.flying = in_air

    def disarm(self) -> None:
        self.flying = False
        self._takeoff_throttle = -1.0

    def landed(self, pos_ned_m: list[float]) -> None:
        """The land detector says landed: hand back to the ground, targets where it stands."""
        self.flying = False
        self._reset(pos_ned_m)

    def stopping_point(
        self, pos_ned_m: list[float], vel_ned_ms: list[float]
    ) -> tuple[float, float, float]:
        """ArduPilot's stopping point: the position plus, along the velocity, the distance
        the square-root controller needs to bring that speed to rest."""
        lim, g = self.limits, self.gains
        (pn, pe, pd), (vn, ve, vd) = pos_ned_m, vel_ned_ms
        speed = math.sqrt(vn * vn + ve * ve)
        if speed > 0.0:
            k = stopping_distance(min(speed, lim.speed_xy_ms), g.pos_ne_p, lim.accel_xy_mss)
            pn, pe = pn + vn * k / speed, pe + ve * k / speed
        if vd != 0.0:
            down = stopping_distance(abs(vd), g.pos_d_p, lim.accel_z_mss)
            pd += down if vd > 0.0 else -down
        return (pn, pe, min(pd, 0.0))

    # ------------------------------------------------------------------ the step
    def update(
        self,
        pos_ned_m: list[float],
        vel_ned_ms: list[float],
        accel_ned_mss: list[float],
        lean_ne: list[float],
        *,
        on_ground: bool,
        landed: bool,
        thrust_n: float,
        dt_s: float,
    ) -> Command:
        if dt_s != self._dt_s:
            self._dt_s = dt_s
            self._verr_alpha = dt_s / (dt_s + 1.0 / (2.0 * math.pi * VEL_ERROR_FILTER_HZ))
        self.armed_s += dt_s
        if self.armed_s < ARMING_DELAY_S:
            return IDLE
        if not self.flying:
            if landed and not self._wants_to_climb(pos_ned_m):
                self._spool = 0.0
                self._reset(pos_ned_m)
                return IDLE  # ground idle
            if on_ground:
                return self._take_off(vel_ned_ms, accel_ned_mss, pos_ned_m, thrust_n, dt_s)
            self._start_flying(pos_ned_m, vel_ned_ms, thrust_n)  # armed in the air, a bounce
        self._shape_target(vel_ned_ms, dt_s)
        a_max = GRAVITY_MSS * math.tan(self.limits.lean_max_deg * _DEG)
        an, ae, ad = self._track(pos_ned_m, vel_ned_ms, on_ground=on_ground, a_max=a_max)
        # Horizontal acceleration -> lean of the thrust vector (within ANGLE_MAX).
        a_xy = math.sqrt(an * an + ae * ae)
        if a_xy > a_max:
            an, ae = an * a_max / a_xy, ae * a_max / a_xy
            self._limit = (an / a_max, ae / a_max)
        elif self._limit[0] or self._limit[1]:
            self._limit = (0.0, 0.0)
        norm = 1.0 / math.sqrt(an * an + ae * ae + GRAVITY_MSS * GRAVITY_MSS)
        # Vertical acceleration -> thrust, boosted by the lean actually flown.
        ln, le = lean_ne
        upright = 1.0 - ln * ln - le * le
        thrust = self.mass_kg * (GRAVITY_MSS - ad) / math.sqrt(upright if upright > 0.25 else 0.25)
        if on_ground and ad > 0.0:
            # Asked down, but the ground holds it: the vertical controller's integrator winds
            # the throttle down to its lower limit, from the hover in about a second
            # (ArduCopter's, too), which the land detector then notices.
            self._wind_down = min(self._wind_down + GRAVITY_MSS * dt_s, GRAVITY_MSS)
            thrust -= self.mass_kg * self._wind_down
        elif self._wind_down:
            self._wind_down = 0.0
        thrust = (
            0.0 if thrust < 0.0 else (self.thrust_max_n if thrust > self.thrust_max_n else thrust)
        )
        return Command(an * norm, ae * norm, thrust)

    def _wants_to_climb(self, pos_ned_m: list[float]) -> bool:
        t = self.target
        if t.vel_ned_ms is not None:
            return t.vel_ned_ms[2] < 0.0
        return t.pos_ned_m is not None and t.pos_ned_m[2] < pos_ned_m[2] - 0.1

    def _take_off(
        self,
        vel_ned_ms: list[float],
        accel_ned_mss: list[float],
        pos_ned_m: list[float],
        thrust_n: float,
        dt_s: float,
    ) -> Command:
        """Spool up, then raise the throttle (TKOFF_SLEW_TIME from idle to full) until the
        vehicle climbs: ArduCopter's auto take-off, before its position controller flies."""
        g, lim = self.gains, self.limits
        if self._spool < 1.0:
            self._spool = min(1.0, self._spool + dt_s / max(g.spool_time_s, 1e-3))
            self._takeoff_throttle = 0.0
            return IDLE
        self._takeoff_throttle = min(
            self._takeoff_throttle + dt_s / max(g.takeoff_slew_s, 1e-3), 0.9
        )
        climbing = -vel_ned_ms[2] >= 0.1 * lim.speed_up_ms
        lifting = -accel_ned_mss[2] >= 0.5 * lim.accel_z_mss
        if self._takeoff_throttle >= 0.9 or climbing or lifting:
            self._start_flying(pos_ned_m, vel_ned_ms, thrust_n)
        return Command(0.0, 0.0, self._takeoff_throttle * self.thrust_max_n)

    def _start_flying(
        self, pos_ned_m: list[float], vel_ned_ms: list[float], thrust_n: float
    ) -> None:
        """Hand the vehicle to the position controller: its target starts where the vehicle
        is and as it moves; the vertical integrator holds the thrust it has now."""
        self.flying = True
        self._takeoff_throttle = -1.0
        self._spool = 1.0
        self._tp[:] = pos_ned_m
        self._tv[:] = vel_ned_ms
        self._ta[0] = self._ta[1] = self._ta[2] = 0.0
        self._i[0] = self._i[1] = 0.0
        self._verr[0] = self._verr[1] = 0.0
        self._i[2] = GRAVITY_MSS - thrust_n / self.mass_kg
        self._hold = None
        self._curve = None
        self._curve_pending = self.target.path and self.target.pos_ned_m is not None

    def _reset(self, pos_ned_m: list[float]) -> None:
        self._tp[:] = pos_ned_m
        self._tv[0] = self._tv[1] = self._tv[2] = 0.0
        self._ta[0] = self._ta[1] = self._ta[2] = 0.0
        self._i[0] = self._i[1] = self._i[2] = 0.0
        self._verr[0] = self._verr[1] = 0.0

    def _shape_target(self, vel_ned_ms: list[float], dt_s: float) -> None:
        """Move the kinematic target toward the position target (or the stopping point) or at
        the commanded velocity: the position error asks for a velocity along the square-root
        curve, the velocity error for an acceleration, within the speed (WPNAV_SPEED, _UP,
        _DN) and acceleration (WPNAV_ACCEL, _ACCEL_Z) limits, the acceleration changing no
        faster than the jerk limits."""
        t, lim, g = self.target, self.limits, self.gains
        tp, tv, ta = self._tp, self._tv, self._ta
        if self._curve_pending:
            self._start_leg()
        if self._curve is not None:
            self._fly_leg(vel_ned_ms, dt_s)
            return
        acc_xy, jerk_xy = lim.accel_xy_mss, g.jerk_xy_msss
        acc_z, jerk_z = lim.accel_z_mss, g.jerk_z_msss
        if t.vel_ned_ms is not None:
            an, ae, ad = self._velocity_accel(t.vel_ned_ms, jerk_xy)
        else:
            goal = t.pos_ned_m
            if goal is None:
                if self._hold is None:
                    self._hold = self.stopping_point(tp, tv)
                goal = self._hold
            en, ee, ed = goal[0] - tp[0], goal[1] - tp[1], goal[2] - tp[2]
            if (
                tv[0] == tv[1] == tv[2] == ta[0] == ta[1] == ta[2] == 0.0
                and -1e-9 < en < 1e-9
                and -1e-9 < ee < 1e-9
                and -1e-9 < ed < 1e-9
            ):
                self.leg_done = True
                return  # there, and still: nothing to shape
            an, ae = shape_pos_xy(en, ee, tv[0], tv[1], lim.speed_xy_ms, acc_xy, jerk_xy / acc_xy)
            ad = shape_pos_z(ed, tv[2], lim.speed_up_ms, lim.speed_dn_ms, acc_z, jerk_z / acc_z)
        # the acceleration turns toward the wanted one at a limited rate (jerk)
        jn, je = an - ta[0], ae - ta[1]
        j_xy = math.sqrt(jn * jn + je * je)
        step = jerk_xy * dt_s
        if j_xy > step:
            jn, je = jn * step / j_xy, je * step / j_xy
        ta[0] += jn
        ta[1] += je
        ta[2] = shape_rate(ta[2], ad, jerk_z * dt_s)
        # While the lean is at its limit and the vehicle lags the target in that direction,
        # the target waits for it (ArduPilot's limit vector): it does not run ahead.
        ln, le = self._limit
        held = (ln or le) and (tv[0] - vel_ned_ms[0]) * ln + (tv[1] - vel_ned_ms[1]) * le > 0.0
        if not held or ta[0] * ln + ta[1] * le <= 0.0:
            tv[0] += ta[0] * dt_s
            tv[1] += ta[1] * dt_s
        if not held or tv[0] * ln + tv[1] * le <= 0.0:
            tp[0] += tv[0] * dt_s
            tp[1] += tv[1] * dt_s
        tv[2] += ta[2] * dt_s
        tp[2] += tv[2] * dt_s
        if t.pos_ned_m is not None or t.vel_ned_ms is None:  # at rest on the goal: stay there
            goal = t.pos_ned_m or self._hold
            if goal is not None and _settled(tp, tv, ta, goal):
                tp[0], tp[1], tp[2] = goal
                tv[0] = tv[1] = tv[2] = ta[0] = ta[1] = ta[2] = 0.0
                self.leg_done = True

    def _start_leg(self) -> None:
        """A route leg flown from rest: its S-curve, within the limits of each axis."""
        self._curve_pending = False
        tp, tv, ta, goal = self._tp, self._tv, self._ta, self.target.pos_ned_m
        assert goal is not None
        moving = abs(tv[0]) + abs(tv[1]) + abs(tv[2]) > 0.1 or abs(ta[0]) + abs(ta[1]) > 0.5
        dn, de, dd = goal[0] - tp[0], goal[1] - tp[1], goal[2] - tp[2]
        length = math.sqrt(dn * dn + de * de + dd * dd)
        if length < 1e-6 and not moving:
            self.leg_done = True  # already there
            return
        if moving:
            return  # not from rest: shaped toward the goal instead
        lim, g = self.limits, self.gains
        across, up = math.sqrt(dn * dn + de * de) / length, abs(dd) / length
        vertical_speed = lim.speed_dn_ms if dd > 0.0 else lim.speed_up_ms

        def along(xy: float, z: float) -> float:  # the limit along the leg
            return min(
                xy / across if across > 1e-9 else math.inf, z / up if up > 1e-9 else math.inf
            )

        self._curve = SCurve(
            length,
            speed=along(lim.speed_xy_ms, vertical_speed),
            accel=along(lim.accel_xy_mss, lim.accel_z_mss),
            jerk=along(g.jerk_path_msss, g.jerk_z_msss),
        )
        self._curve_from = (tp[0], tp[1], tp[2])
        self._curve_dir = (dn / length, de / length, dd / length)
        self._curve_s = 0.0

    def _fly_leg(self, vel_ned_ms: list[float], dt_s: float) -> None:
        """The target along the leg's S-curve. Its clock slows while the vehicle lags far
        behind and stops while the lean is at its limit (ArduPilot's track scaling): the
        target never runs away from a vehicle the wind holds back."""
        curve = self._curve
        assert curve is not None
        (fn, fe, fd), (un, ue, ud) = self._curve_from, self._curve_dir
        ln, le = self._limit
        held = (ln or le) and (self._tv[0] - vel_ned_ms[0]) * ln + (
            self._tv[1] - vel_ned_ms[1]
        ) * le > 0.0
        pace = 0.0 if held else (1.0 if self._lag < 0.5 else max(0.0, 2.0 * (1.0 - self._lag)))
        self._curve_s += dt_s * pace
        dist, speed, accel = curve.at(self._curve_s)
        tp, tv, ta = self._tp, self._tv, self._ta
        tp[0], tp[1], tp[2] = fn + un * dist, fe + ue * dist, fd + ud * dist
        tv[0], tv[1], tv[2] = un * speed, ue * speed, ud * speed
        ta[0], ta[1], ta[2] = un * accel, ue * accel, ud * accel
        if self._curve_s >= curve.duration:
            goal = self.target.pos_ned_m
            assert goal is not None
            tp[0], tp[1], tp[2] = goal
            self._curve = None
            self.leg_done = True

    def _velocity_accel(
        self, vel: tuple[float, float, float], jerk_xy: float
    ) -> tuple[float, float, float]:
        """The target's acceleration toward a commanded velocity (square-root controller in
        jerk), the velocity first bounded by the speed limits."""
        lim, g, tv = self.limits, self.gains, self._tv
        vn, ve, vd = vel
        v_xy = math.sqrt(vn * vn + ve * ve)
        if v_xy > lim.speed_xy_ms:
            vn, ve = vn * lim.speed_xy_ms / v_xy, ve * lim.speed_xy_ms / v_xy
        vd = max(-lim.speed_up_ms, min(lim.speed_dn_ms, vd))
        en, ee = vn - tv[0], ve - tv[1]
        err = math.sqrt(en * en + ee * ee)
        an = ae = 0.0
        if err > 0.0:
            acc = lim.accel_xy_mss
            a = min(sqrt_controller(err, jerk_xy / acc, jerk_xy), acc) / err
            an, ae = en * a, ee * a
        acc_z, jerk_z = lim.accel_z_mss, g.jerk_z_msss
        ad = max(-acc_z, min(acc_z, sqrt_controller(vd - tv[2], jerk_z / acc_z, jerk_z)))
        return an, ae, ad

    def _track(
        self, pos: list[float], vel: list[float], *, on_ground: bool, a_max: float
    ) -> tuple[float, float, float]:
        """The acceleration that brings the vehicle onto the kinematic target (NED, m/s²)."""
        g, lim, tp, tv, ta, i = self.gains, self.limits, self._tp, self._tv, self._ta, self._i
        dt_s = self._dt_s
        # Horizontal: position error (leashed) -> velocity -> acceleration.
        en, ee = tp[0] - pos[0], tp[1] - pos[1]
        err = math.sqrt(en * en + ee * ee)
        vn, ve = tv[0], tv[1]
        if err > 1e-9:
            leash = stopping_distance(lim.speed_xy_ms, g.pos_ne_p, lim.accel_xy_mss)
            self._lag = err / leash
            if err > leash:  # the target ran ahead of what the vehicle can fly: pull it back
                en, ee, err = en * leash / err, ee * leash / err, leash
                if self._curve is None:  # (a leg's target waits on its own clock instead)
                    tp[0], tp[1] = pos[0] + en, pos[1] + ee
            corr = sqrt_controller(err, g.pos_ne_p, lim.accel_xy_mss) / err
            vn += en * corr
            ve += ee * corr
        else:
            self._lag = 0.0
        # the velocity error through PSC_VELXY_FLTE's low-pass filter, as ArduCopter's
        f, k = self._verr, self._verr_alpha
        f[0] += (vn - vel[0] - f[0]) * k
        f[1] += (ve - vel[1] - f[1]) * k
        an = ta[0] + g.vel_ne_p * f[0] + i[0]
        ae = ta[1] + g.vel_ne_p * f[1] + i[1]
        if an * an + ae * ae < a_max * a_max:  # the integrator stops while the lean is limited
            i[0] += g.vel_ne_i * f[0] * dt_s
            i[1] += g.vel_ne_i * f[1] * dt_s
            i_xy = i[0] * i[0] + i[1] * i[1]
            imax = g.vel_ne_imax_mss
            if i_xy > imax * imax:
                i_xy = math.sqrt(i_xy)
                i[0], i[1] = i[0] * imax / i_xy, i[1] * imax / i_xy
        # Vertical.
        ed = tp[2] - pos[2]
        leash_d = stopping_distance(
            max(lim.speed_up_ms, lim.speed_dn_ms), g.pos_d_p, lim.accel_z_mss
        )
        if ed > leash_d or ed < -leash_d:
            ed = leash_d if ed > 0.0 else -leash_d
            tp[2] = pos[2] + ed
        ev = tv[2] + sqrt_controller(ed, g.pos_d_p, lim.accel_z_mss) - vel[2]
        ad = ta[2] + g.vel_d_p * ev + i[2]
        if not on_ground:
            iz = i[2] + g.vel_d_i * ev * dt_s
            i[2] = -GRAVITY_MSS if iz < -GRAVITY_MSS else (GRAVITY_MSS if iz > GRAVITY_MSS else iz)
        return an, ae, ad


def _settled(
    tp: list[float], tv: list[float], ta: list[float], goal: tuple[float, float, float]
) -> bool:
    """The kinematic target is on its goal and at rest, to a millimetre."""
    return (
        abs(tp[0] - goal[0]) + abs(tp[1] - goal[1]) + abs(tp[2] - goal[2]) < 1e-3
        and abs(tv[0]) + abs(tv[1]) + abs(tv[2]) < 1e-3
        and abs(ta[0]) + abs(ta[1]) + abs(ta[2]) < 1e-2
    )
