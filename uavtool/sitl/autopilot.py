"""The vehicle's brain: flight modes, arming, guided targets, failsafes, battery and gimbal.

It knows nothing of sockets or MAVLink framing: the protocol layer (``gcs.py``) turns
messages into calls here, and ``telemetry.py`` reads the state back out. Everything is
driven by ``tick(now_ns)`` on the simulation clock, so a flight is the same at any speed-up.
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Sequence

from uavtool.geo import GeoPoint, enu_from_geo, geo_from_enu, wrap_180
from uavtool.mavlink.dialect import mavlink
from uavtool.sitl.auto import AutoMission
from uavtool.sitl.avoid import adjust_velocity
from uavtool.sitl.battery import Battery
from uavtool.sitl.crash import Collisions
from uavtool.sitl.fence import Fence
from uavtool.sitl.mount import Mount
from uavtool.sitl.obstacles import Prism
from uavtool.sitl.params import ParamStore, highest
from uavtool.sitl.physics import Multicopter, State, Target
from uavtool.sitl.prearm import boot_failure
from uavtool.sitl.shutter import Shutter
from uavtool.sitl.state import (
    ACCEPTED,
    ARMABLE_MODES,
    Gimbal,
    Mode,
    Result,
    denied,
    failed,
)
from uavtool.sitl.wind import WindParams
from uavtool.sitl.yaw import travel_yaw_deg

FORCE_MAGIC = 21196  # ArduPilot's "force" value for ARM_DISARM param2
_NS = 1_000_000_000
_SEV = mavlink  # severities: MAV_SEVERITY_*


class Autopilot:
    """An ArduCopter-like autopilot around a :class:`Multicopter`."""

    def __init__(
        self,
        *,
        home: GeoPoint,
        home_heading_deg: float,
        params: ParamStore,
        seed: int,
        obstacles: Sequence[Prism] = (),
        body_radius_m: float = 0.4,
        arming_settle_s: float = 0.0,
        mount_roll_trim_deg: float = 0.0,
    ) -> None:
        self.params = params
        self.mount = Mount.at_boot(params, roll_trim_deg=mount_roll_trim_deg)
        self.arming_settle_s = arming_settle_s
        self.home = home
        # Separate streams: how many sensor readings are sent (clients, rates) must not
        # change the gusts, so the trajectory depends only on the seed and the commands.
        self.noise_rng = random.Random(seed * 2 + 1)
        self.vehicle = Multicopter(
            yaw_deg=home_heading_deg % 360.0,
            rng=random.Random(seed * 2),
            home_alt_amsl_m=home.alt_amsl_m,
        )
        self.mode = Mode.STABILIZE
        self.armed = False
        self.now_ns = 0
        self.gimbal = Gimbal(pitch_deg=0.0, target_pitch_deg=0.0)
        self.gimbal_owner = (0, 0)  # (sysid, compid) in primary control of the gimbal
        self.mission = AutoMission(self)
        self.shutter = Shutter()  # DO_DIGICAM_CONTROL / IMAGE_START_CAPTURE
        self.events: deque[tuple[int, str]] = deque()  # (MAV_SEVERITY, text) to send as STATUSTEXT
        self.failsafe_gcs = False
        self.failsafe_battery = False
        self.last_gcs_heartbeat_ns: int | None = None
        self.speed_override_ms: float | None = None
        self.taking_off = False
        self._landed_since_ns: int | None = 0
        self._rtl_stage = ""
        self._rtl_alt = 0.0
        self._rtl_loiter_until_ns = 0
        self.land_ne = (0.0, 0.0)
        self._velocity_deadline_ns = 0
        self._velocity_request = (0.0, 0.0, 0.0)  # a GUIDED velocity as asked, before avoidance
        self.battery = Battery(params)
        self.collisions = Collisions(obstacles, body_radius_m)
        self.fence = Fence(params)
        self.apply_params()

    # ------------------------------------------------------------------ params
    def apply_params(self) -> None:
        """Refresh limits, wind and noise from the parameter table."""
        p = self.params
        lim = self.vehicle.limits
        lim.speed_xy_ms = max(p["WPNAV_SPEED"], 20.0) / 100.0
        if self.speed_override_ms is not None:
            lim.speed_xy_ms = self.speed_override_ms
        lim.speed_up_ms = max(p["WPNAV_SPEED_UP"], 10.0) / 100.0
        lim.speed_dn_ms = max(p["WPNAV_SPEED_DN"], 10.0) / 100.0
        lim.accel_xy_mss = max(p["WPNAV_ACCEL"], 50.0) / 100.0
        lim.accel_z_mss = max(p["WPNAV_ACCEL_Z"], 50.0) / 100.0
        lim.yaw_rate_dps = max(p["ATC_SLEW_YAW"], 500.0) / 100.0
        lim.lean_max_deg = max(p["ANGLE_MAX"], 1000.0) / 100.0
        self.vehicle.air.set_params(wind_params(p))
        g = self.vehicle.gains
        g.pos_ne_p, g.vel_ne_p, g.vel_ne_i = p["PSC_POSXY_P"], p["PSC_VELXY_P"], p["PSC_VELXY_I"]
        g.vel_ne_imax_mss = p["PSC_VELXY_IMAX"] / 100.0
        g.pos_d_p, g.vel_d_p = p["PSC_POSZ_P"], p["PSC_VELZ_P"]
        g.jerk_xy_msss, g.jerk_path_msss = p["PSC_JERK_XY"], p["WPNAV_JERK"]
        g.jerk_z_msss = p["PSC_JERK_Z"]
        g.input_tc_s = p["ATC_INPUT_TC"]
        g.accel_rp_max_dss = min(p["ATC_ACCEL_R_MAX"], p["ATC_ACCEL_P_MAX"]) / 100.0
        g.accel_y_max_dss = p["ATC_ACCEL_Y_MAX"] / 100.0
        g.spool_time_s = p["MOT_SPOOL_TIME"]
        g.takeoff_slew_s = p["TKOFF_SLEW_TIME"]

    # ------------------------------------------------------------------ state read-outs
    @property
    def state(self) -> State:
        return self.vehicle.state

    @property
    def on_ground(self) -> bool:
        """Landed, as ArduCopter's land detector says it (not just touching the ground)."""
        return self.vehicle.state.landed

    def alt_rel_m(self) -> float:
        return -self.vehicle.state.pos_ned_m[2]

    def position_geo(self) -> GeoPoint:
        n, e, d = self.vehicle.state.pos_ned_m
        return geo_from_enu(self.home, e, n, -d)

    def ned_of(self, point: GeoPoint) -> tuple[float, float, float]:
        east, north, up = enu_from_geo(self.home, point)
        return (north, east, -up)

    def say(self, severity: int, text: str) -> None:
        self.events.append((severity, text[:50]))

    @property
    def crashed(self) -> bool:
        return self.collisions.crashed

    # ------------------------------------------------------------------ commands
    def arm(self, *, force: bool) -> Result:
        if self.crashed:  # even forced: the airframe is wrecked until the vehicle reboots
            return failed("Arm: vehicle crashed; reboot to arm")
        if self.armed:
            return ACCEPTED
        if not force and self.params["ARMING_CHECK"] != 0:
            if self.mode not in ARMABLE_MODES:
                return failed(f"Arm: Mode not armable ({self.mode.name})")
            if self.battery.voltage() < self.params["BATT_LOW_VOLT"]:
                return failed("PreArm: Battery below minimum arming voltage")
            why = boot_failure(self.now_ns, self.arming_settle_s) or self.mount.pre_arm_failure(
                self.params
            )
            if why is not None:
                return failed(f"Arm: {why}")
        self.armed = True
        self.vehicle.arm()
        self.vehicle.set_target(Target(yaw_deg=None))
        self._landed_since_ns = self.now_ns
        self.say(mavlink.MAV_SEVERITY_INFO, "Arming motors")
        return ACCEPTED

    def disarm(self, *, force: bool, reason: str = "Disarming motors") -> Result:
        if not self.armed:
            return ACCEPTED
        if not force and not self.on_ground:
            return denied("Disarm: vehicle is flying (use force)")
        self.armed = False
        self.taking_off = False
        self.vehicle.disarm()
        self.mission.stop()
        self.say(mavlink.MAV_SEVERITY_INFO, reason)
        return ACCEPTED

    def set_mode(self, mode: Mode) -> Result:
        if mode == Mode.AUTO and not self.mission.has_nav_items():
            return failed("Mode change to AUTO failed: no mission")
        if (
            mode == Mode.AUTO
            and self.armed
            and self.on_ground
            and not self.mission.starts_with_takeoff()
        ):
            return failed("Auto: Missing Takeoff Cmd")
        if mode == self.mode:
            return ACCEPTED
        self.mode = mode
        # ArduCopter: a mode change during a breach is someone taking control to recover (or
        # the breach's own action): the fence lets them fly for 10 s before it acts again
        if self.params["FENCE_ACTION"] != 0 and self.fence.manual_recovery_start(self.now_ns):
            self.say(mavlink.MAV_SEVERITY_INFO, "Manual recovery started")
        self.taking_off = False
        self.speed_override_ms = None
        self.apply_params()
        if mode == Mode.AUTO:
            self.mission.start()
        else:
            self.mission.stop()
        if mode == Mode.RTL:
            self._rtl_stage = "climb"
        if mode == Mode.LAND:
            self.land_ne = (self.state.pos_ned_m[0], self.state.pos_ned_m[1])
        if mode in (
            Mode.LOITER,
            Mode.BRAKE,
            Mode.GUIDED,
            Mode.STABILIZE,
            Mode.ALT_HOLD,
            Mode.POSHOLD,
        ):
            self.vehicle.set_target(Target(yaw_deg=None))  # brake and hold
        return ACCEPTED

    def takeoff(self, alt_m: float) -> Result:
        """NAV_TAKEOFF in GUIDED to ``alt_m`` above home. DENIED when an obstacle is in the way
        of the body sphere's climb (as an upward proximity sensor would see it)."""
        if self.crashed:
            return failed("Takeoff: vehicle crashed")
        if self.mode != Mode.GUIDED:
            return failed(f"Takeoff: needs GUIDED mode, not {self.mode.name}")
        if not self.armed:
            return failed("Takeoff: vehicle not armed")
        if not self.on_ground:
            return failed("Takeoff: already flying")
        if not 0.0 < alt_m < math.inf:
            return denied(f"Takeoff: altitude must be above 0 m, got {alt_m:g}")
        fence = self.fence.check_target((self.state.pos_ned_m[0], self.state.pos_ned_m[1], -alt_m))
        if fence is not None:
            return fence
        blocked = self.collisions.takeoff_obstacle(self.state.pos_ned_m, alt_m)
        if blocked is not None:
            return blocked
        self.start_takeoff(alt_m)
        return ACCEPTED

    def start_takeoff(self, alt_m: float) -> None:
        n, e, _ = self.state.pos_ned_m
        self.taking_off = True
        self.vehicle.set_target(Target(pos_ned_m=(n, e, -alt_m)))

    def guided_position(
        self,
        pos_ned_m: tuple[float, float, float],
        *,
        yaw_deg: float | None = None,
        switch_mode: bool = False,
    ) -> Result:
        if self.mode != Mode.GUIDED:
            if not switch_mode:
                return failed(f"Guided: not in GUIDED mode ({self.mode.name})")
            self.set_mode(Mode.GUIDED)
        if not self.armed or (self.on_ground and not self.taking_off):
            return failed("Guided: vehicle is not flying")
        if not all(math.isfinite(v) for v in pos_ned_m):
            return denied("Guided: target position is not finite")
        if pos_ned_m[2] > 0.0:
            return denied(f"Guided: target {-pos_ned_m[2]:.0f} m is below ground")
        fence = self.fence.check_target(pos_ned_m)
        if fence is not None:
            return fence
        if yaw_deg is None:
            n, e, _ = self.state.pos_ned_m
            yaw_deg = travel_yaw_deg(
                int(self.params["WP_YAW_BEHAVIOR"]), from_ne_m=(n, e), to_ne_m=pos_ned_m[:2]
            )
        yaw = yaw_deg if yaw_deg is not None else self.vehicle.target.yaw_deg
        self.taking_off = False
        self.vehicle.set_target(Target(pos_ned_m=pos_ned_m, yaw_deg=yaw))
        return ACCEPTED

    def guided_velocity(
        self, vel_ned_ms: tuple[float, float, float], *, yaw_deg: float | None = None
    ) -> Result:
        if self.mode != Mode.GUIDED:
            return failed("Guided: not in GUIDED mode")
        if not self.armed:
            return failed("Guided: vehicle not armed")
        if not all(math.isfinite(v) for v in vel_ned_ms):
            return denied("Guided: target velocity is not finite")
        vel_ned_ms = _bounded_velocity(vel_ned_ms)
        self._velocity_request = vel_ned_ms
        self.taking_off = False
        self._velocity_deadline_ns = (
            self.now_ns + 3 * _NS
        )  # ArduCopter: stop after 3 s without an update
        self.vehicle.set_target(
            Target(
                vel_ned_ms=vel_ned_ms,
                yaw_deg=yaw_deg if yaw_deg is not None else self.vehicle.target.yaw_deg,
            )
        )
        return ACCEPTED

    def condition_yaw(
        self, angle_deg: float, rate_dps: float, direction: int, relative: bool
    ) -> Result:
        if self.mode not in (Mode.GUIDED, Mode.AUTO):
            return failed(f"Yaw: needs GUIDED or AUTO, not {self.mode.name}")
        if not self.armed:
            return failed("Yaw: vehicle not armed")
        if not math.isfinite(angle_deg):
            return denied("Yaw: angle is not finite")
        rate_dps = rate_dps if math.isfinite(rate_dps) else 0.0
        current = self.state.yaw_deg
        if relative:
            step = abs(angle_deg) * (-1.0 if direction < 0 else 1.0)
            target = (current + step) % 360.0
        else:
            target = angle_deg % 360.0
        t = self.vehicle.target
        self.vehicle.target = Target(
            pos_ned_m=t.pos_ned_m,
            vel_ned_ms=t.vel_ned_ms,
            yaw_deg=target,
            yaw_rate_dps=rate_dps if rate_dps > 0 else None,
        )
        return ACCEPTED

    def change_speed(self, speed_type: int, speed_ms: float) -> Result:
        if not math.isfinite(speed_ms):
            return denied("Change speed: speed is not finite")
        if speed_ms < 0:  # -1 means "no change"
            return ACCEPTED
        # Each speed within its parameter's range, as ArduCopter bounds what it is asked for
        # (1e38 m/s was taken as it came).
        if speed_type in (0, 1):
            self.speed_override_ms = min(max(0.2, speed_ms), _MAX_XY_MS)
            self.vehicle.limits.speed_xy_ms = self.speed_override_ms
        elif speed_type == 2:
            self.vehicle.limits.speed_up_ms = min(max(0.1, speed_ms), _MAX_UP_MS)
        elif speed_type == 3:
            self.vehicle.limits.speed_dn_ms = min(max(0.1, speed_ms), _MAX_DN_MS)
        else:
            return denied(f"Change speed: unknown speed type {speed_type}")
        return ACCEPTED

    def set_gimbal(
        self, *, pitch_deg: float | None, yaw_deg: float | None, yaw_locked: bool = False
    ) -> Result:
        if not self.mount.present:
            return failed("")  # ArduPilot: FAILED, and no STATUSTEXT
        g = self.gimbal
        if pitch_deg is not None and math.isfinite(pitch_deg):
            low, high = self.params["MNT1_PITCH_MIN"], self.params["MNT1_PITCH_MAX"]
            g.target_pitch_deg = min(max(pitch_deg, low), high)
        if yaw_deg is not None and math.isfinite(yaw_deg):
            if yaw_locked:
                # Earth-frame heading, re-evaluated against the vehicle heading as it turns.
                g.yaw_locked = True
                g.target_yaw_deg = yaw_deg % 360.0
            else:
                g.yaw_locked = False
                low, high = self.params["MNT1_YAW_MIN"], self.params["MNT1_YAW_MAX"]
                g.target_yaw_deg = min(max(wrap_180(yaw_deg), low), high)
        return ACCEPTED

    def gcs_heartbeat(self) -> None:
        self.last_gcs_heartbeat_ns = self.now_ns
        if self.failsafe_gcs:
            self.failsafe_gcs = False
            self.say(mavlink.MAV_SEVERITY_CRITICAL, "GCS Failsafe Cleared")

    # ------------------------------------------------------------------ simulation
    def tick(self, now_ns: int, dt_s: float) -> None:
        """Advance the vehicle to ``now_ns`` (one physics step of ``dt_s``)."""
        self.now_ns = now_ns
        if self.armed:
            self._run_mode()
        self.vehicle.step(dt_s)
        if self.armed and (self.collisions.has_obstacles or self.vehicle.touchdown is not None):
            reason = self.collisions.check(self.vehicle)
            if reason is not None:
                self.crash(reason)
        self._update_gimbal(dt_s)
        v = self.vehicle
        self.battery.drain(motor_power_w=v.body.watts_per_newton * v.state.thrust_n, dt_s=dt_s)
        self._check_fence()
        self._check_failsafes()
        self._check_landed()

    def crash(self, reason: str) -> None:
        """Crash now: say ``reason`` (EMERGENCY), cut the motors and disarm; the wreck falls to
        the ground and refuses to arm until the vehicle restarts."""
        self.collisions.record_crash(reason)
        self.say(mavlink.MAV_SEVERITY_EMERGENCY, reason)
        s = self.vehicle.state
        # It stopped against what it hit and its propellers are broken: it can only fall.
        s.vel_ned_ms[0] = s.vel_ned_ms[1] = 0.0
        s.vel_ned_ms[2] = max(s.vel_ned_ms[2], 0.0)
        s.thrust_n = 0.0
        self.disarm(force=True, reason="Crash: disarming motors")

    def _run_mode(self) -> None:
        mode = self.mode
        if mode == Mode.GUIDED:
            t = self.vehicle.target
            if t.vel_ned_ms is not None and self.now_ns > self._velocity_deadline_ns:
                self.vehicle.set_target(Target(yaw_deg=t.yaw_deg))  # stale velocity stream: stop
            elif t.vel_ned_ms is not None:
                self._avoid_fence(t)
            if self.taking_off and self.alt_rel_m() >= -(t.pos_ned_m or (0, 0, 0))[2] - 0.1:
                self.taking_off = False
        elif mode == Mode.AUTO:
            self.mission.update()
        elif mode == Mode.RTL:
            self._run_rtl()
        elif mode == Mode.LAND:
            self.descend()

    def _avoid_fence(self, t: Target) -> None:
        """The velocity asked for, cut to what stops the vehicle at the fence (AC_Avoid)."""
        v, g = self.vehicle, self.vehicle.gains
        vel = adjust_velocity(
            self._velocity_request,
            v.state.pos_ned_m,
            fence=self.fence,
            params=self.params,
            pos_p=(g.pos_ne_p, g.pos_d_p),
            accel_mss=(v.limits.accel_xy_mss, v.limits.accel_z_mss),
        )
        if vel != t.vel_ned_ms:
            v.target = Target(vel_ned_ms=vel, yaw_deg=t.yaw_deg, yaw_rate_dps=t.yaw_rate_dps)

    def descend(self) -> None:
        speed = self.params["LAND_SPEED"] / 100.0
        if self.alt_rel_m() > 10.0:
            high = self.params["LAND_SPEED_HIGH"] or self.params["WPNAV_SPEED_DN"]
            speed = high / 100.0
        t = self.vehicle.target
        n, e, _ = self.state.pos_ned_m
        # Hold the horizontal position where landing began, descend at the landing rate.
        land_n, land_e = self.land_ne
        vn = max(-2.0, min(2.0, land_n - n))
        ve = max(-2.0, min(2.0, land_e - e))
        self.vehicle.target = Target(vel_ned_ms=(vn, ve, speed), yaw_deg=t.yaw_deg)

    def _run_rtl(self) -> None:
        rtl_alt = max(self.params["RTL_ALT"] / 100.0, 2.0)
        n, e, d = self.state.pos_ned_m
        speed = self.params["RTL_SPEED"] / 100.0
        if speed > 0:
            self.vehicle.limits.speed_xy_ms = speed
        if self._rtl_stage == "climb":
            alt = max(-d, rtl_alt)
            safe_alt = self.fence.safe_alt_max_m()
            if safe_alt is not None:  # return under the fence, descending first if above it
                alt = min(alt, safe_alt)
            self._rtl_alt = alt
            stop_n, stop_e, _ = self.vehicle.stopping_point()  # ArduCopter's RTL starts there
            if self.vehicle.target.pos_ned_m != (stop_n, stop_e, -alt):
                self.vehicle.set_target(Target(pos_ned_m=(stop_n, stop_e, -alt)))
            self._rtl_stage = "climbing"
        climb = self.vehicle.target.pos_ned_m
        if (
            self._rtl_stage == "climbing"
            and -d >= self._rtl_alt - 0.2
            and self.vehicle.control.leg_done
            and (climb is None or math.hypot(n - climb[0], e - climb[1]) < 1.0)
            and math.hypot(self.state.vel_ned_ms[0], self.state.vel_ned_ms[1]) < 0.5
        ):  # up, and braked to where it could stop: then home
            self.vehicle.set_target(Target(pos_ned_m=(0.0, 0.0, -self._rtl_alt), path=True))
            self._rtl_stage = "return"
        if (
            self._rtl_stage == "return"
            and self.vehicle.control.leg_done
            and math.hypot(n, e) < 0.5
            and abs(self.state.vel_ned_ms[0]) < 0.2
        ):
            # ArduCopter loiters above home for RTL_LOIT_TIME before its final descent.
            self._rtl_stage = "loiter"
            self._rtl_loiter_until_ns = self.now_ns + int(self.params["RTL_LOIT_TIME"] * 1e6)
        if self._rtl_stage == "loiter" and self.now_ns >= self._rtl_loiter_until_ns:
            self._rtl_stage = "land"
            self.land_ne = (0.0, 0.0)
            self.say(mavlink.MAV_SEVERITY_INFO, "RTL: landing at home")
        if self._rtl_stage == "land":
            self.descend()

    def _update_gimbal(self, dt_s: float) -> None:
        g = self.gimbal
        step = g.rate_dps * dt_s
        g.pitch_deg += max(-step, min(step, g.target_pitch_deg - g.pitch_deg))
        target_yaw = g.target_yaw_deg
        if g.yaw_locked:
            target_yaw = wrap_180(g.target_yaw_deg - self.state.yaw_deg)
        g.yaw_deg += max(-step, min(step, wrap_180(target_yaw - g.yaw_deg)))

    def battery_current_a(self) -> float:
        return self.battery.current_a

    def _check_failsafes(self) -> None:
        p = self.params
        action = int(p["FS_GCS_ENABLE"])
        if (
            action
            and self.armed
            and not self.failsafe_gcs
            and self.last_gcs_heartbeat_ns is not None
            and self.now_ns - self.last_gcs_heartbeat_ns > p["FS_GCS_TIMEOUT"] * _NS
        ):
            self.failsafe_gcs = True
            self.say(mavlink.MAV_SEVERITY_CRITICAL, "GCS Failsafe")
            self._failsafe_action(
                Mode.LAND if action in (4, 5) else Mode.RTL, keep_auto=action == 2
            )
        if self.armed and not self.failsafe_battery and self.battery.voltage() < p["BATT_LOW_VOLT"]:
            self.failsafe_battery = True
            self.say(mavlink.MAV_SEVERITY_CRITICAL, "Battery 1 is low")
            act = int(p["BATT_FS_LOW_ACT"])
            if act:
                mode = Mode.LAND if act in (1, 4) else Mode.RTL  # 3, 4: SmartRTL → RTL, LAND
                self._failsafe_action(mode, keep_auto=False)

    def _check_fence(self) -> None:
        breach = self.fence.check(self.state.pos_ned_m, self.now_ns)
        if breach is None or not self.armed:
            return
        self.say(mavlink.MAV_SEVERITY_NOTICE, breach.text)
        if breach.mode is None:
            return
        if self.on_ground and not self.taking_off:
            self.disarm(force=True, reason="Fence: disarming on the ground")
        else:
            self.set_mode(breach.mode)

    def _failsafe_action(self, mode: Mode, *, keep_auto: bool) -> None:
        if self.on_ground:
            self.disarm(force=True, reason="Failsafe: disarming on the ground")
            return
        if keep_auto and self.mode == Mode.AUTO:
            return
        if self.mode not in (Mode.RTL, Mode.LAND) or mode == Mode.LAND:
            self.set_mode(mode)

    def _check_landed(self) -> None:
        if not self.armed:
            self._landed_since_ns = None
            return
        if not self.on_ground or self.taking_off:
            self._landed_since_ns = None
            return
        if self._landed_since_ns is None:
            self._landed_since_ns = self.now_ns
            if self.mission.landing():
                self.mission.land_complete()
            if self.mode in (Mode.LAND, Mode.RTL) or (
                self.mode == Mode.AUTO and not self.mission.running
            ):
                self.disarm(force=True, reason="Land complete: disarming")
            return
        delay = self.params["DISARM_DELAY"]
        if delay > 0 and self.now_ns - self._landed_since_ns > delay * _NS:
            self.disarm(force=True, reason="Auto disarm: landed")

    @property
    def in_failsafe(self) -> bool:
        return self.failsafe_gcs or self.failsafe_battery

    def landed_state(self) -> int:
        if self.crashed and not self.on_ground:
            return int(mavlink.MAV_LANDED_STATE_IN_AIR)  # falling
        if not self.armed or (self.on_ground and not self.taking_off):
            return int(mavlink.MAV_LANDED_STATE_ON_GROUND)
        if self.taking_off:
            return int(mavlink.MAV_LANDED_STATE_TAKEOFF)
        if (
            self.mode == Mode.LAND
            or (self.mode == Mode.RTL and self._rtl_stage == "land")
            or self.mission.landing()
        ):
            return int(mavlink.MAV_LANDED_STATE_LANDING)
        return int(mavlink.MAV_LANDED_STATE_IN_AIR)


_MAX_XY_MS = highest("WPNAV_SPEED") / 100.0
_MAX_UP_MS = highest("WPNAV_SPEED_UP") / 100.0
_MAX_DN_MS = highest("WPNAV_SPEED_DN") / 100.0
"""The fastest the vehicle is ever asked to go: the top of each speed parameter's range."""


def _bounded_velocity(vel_ned_ms: tuple[float, float, float]) -> tuple[float, float, float]:
    """A velocity target scaled down to the horizontal speed limit and clamped to the climb
    and descent limits (north, east, down)."""
    n, e, d = vel_ned_ms
    across = math.hypot(n, e)
    if across > _MAX_XY_MS:
        n, e = n * _MAX_XY_MS / across, e * _MAX_XY_MS / across
    return n, e, min(max(d, -_MAX_UP_MS), _MAX_DN_MS)


def wind_params(p: ParamStore) -> WindParams:
    """The SIM_WIND_* parameters as the wind model takes them."""
    return WindParams(
        speed_ms=p["SIM_WIND_SPD"],
        from_deg=p["SIM_WIND_DIR"],
        up_deg=p["SIM_WIND_DIR_Z"],
        turbulence_ms=p["SIM_WIND_TURB"],
        change_tc_s=p["SIM_WIND_TC"],
        profile=int(p["SIM_WIND_T"]),
        profile_alt_m=p["SIM_WIND_T_ALT"],
        profile_coef=p["SIM_WIND_T_COEF"],
    )
