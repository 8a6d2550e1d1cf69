"""Telemetry: what the vehicle streams, how often, and how each message is built.

Rates are per link and in simulation time. Defaults follow what ground stations expect
from an ArduCopter; SET_MESSAGE_INTERVAL and REQUEST_DATA_STREAM change them per link.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from typing import Any

from uavtool.geo import wrap_180
from uavtool.mavlink.dialect import mavlink
from uavtool.sitl.autopilot import Autopilot
from uavtool.sitl.mount import gimbal_quaternion
from uavtool.sitl.state import Mode

M = mavlink
_NS = 1_000_000_000

# Default stream rates, Hz.
DEFAULT_RATES_HZ: dict[int, float] = {
    M.MAVLINK_MSG_ID_HEARTBEAT: 1.0,
    M.MAVLINK_MSG_ID_SYS_STATUS: 1.0,
    M.MAVLINK_MSG_ID_SYSTEM_TIME: 1.0,
    M.MAVLINK_MSG_ID_GPS_RAW_INT: 2.0,
    M.MAVLINK_MSG_ID_ATTITUDE: 10.0,
    M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: 10.0,
    M.MAVLINK_MSG_ID_LOCAL_POSITION_NED: 10.0,
    M.MAVLINK_MSG_ID_VFR_HUD: 4.0,
    M.MAVLINK_MSG_ID_BATTERY_STATUS: 1.0,
    M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: 1.0,
    M.MAVLINK_MSG_ID_MISSION_CURRENT: 1.0,
    M.MAVLINK_MSG_ID_HOME_POSITION: 0.5,
    M.MAVLINK_MSG_ID_GIMBAL_DEVICE_ATTITUDE_STATUS: 10.0,
    M.MAVLINK_MSG_ID_GIMBAL_MANAGER_STATUS: 1.0,
}

# REQUEST_DATA_STREAM groups (ArduPilot's mapping of the legacy stream ids).
DATA_STREAMS: dict[int, tuple[int, ...]] = {
    M.MAV_DATA_STREAM_EXTENDED_STATUS: (
        M.MAVLINK_MSG_ID_SYS_STATUS,
        M.MAVLINK_MSG_ID_GPS_RAW_INT,
        M.MAVLINK_MSG_ID_MISSION_CURRENT,
    ),
    M.MAV_DATA_STREAM_POSITION: (
        M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
        M.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    ),
    M.MAV_DATA_STREAM_EXTRA1: (M.MAVLINK_MSG_ID_ATTITUDE,),
    M.MAV_DATA_STREAM_EXTRA2: (M.MAVLINK_MSG_ID_VFR_HUD,),
    M.MAV_DATA_STREAM_EXTRA3: (
        M.MAVLINK_MSG_ID_SYSTEM_TIME,
        M.MAVLINK_MSG_ID_BATTERY_STATUS,
        M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE,
        M.MAVLINK_MSG_ID_GIMBAL_DEVICE_ATTITUDE_STATUS,
    ),
}

_SENSORS = (
    M.MAV_SYS_STATUS_SENSOR_3D_GYRO
    | M.MAV_SYS_STATUS_SENSOR_3D_ACCEL
    | M.MAV_SYS_STATUS_SENSOR_3D_MAG
    | M.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
    | M.MAV_SYS_STATUS_SENSOR_GPS
    | M.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
    | M.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
    | M.MAV_SYS_STATUS_SENSOR_YAW_POSITION
    | M.MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
    | M.MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
    | M.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
    | M.MAV_SYS_STATUS_AHRS
    | M.MAV_SYS_STATUS_SENSOR_BATTERY
    | M.MAV_SYS_STATUS_PREARM_CHECK
)
CAPABILITIES = (
    M.MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT
    | M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
    | M.MAV_PROTOCOL_CAPABILITY_MISSION_INT
    | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
    | M.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_LOCAL_NED
    | M.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT
    | M.MAV_PROTOCOL_CAPABILITY_MAVLINK2
)
FIRMWARE_VERSION = (4 << 24) | (5 << 16) | (7 << 8) | 255  # reported as Copter 4.5.7 official
_GUIDED_FLAG_MODES = frozenset(
    {Mode.GUIDED, Mode.AUTO, Mode.RTL, Mode.LAND, Mode.LOITER, Mode.BRAKE, Mode.POSHOLD}
)


class Telemetry:
    """Builds the vehicle's messages from the autopilot state."""

    def __init__(self, ap: Autopilot, *, sysid: int, instance: int, start_unix_us: int) -> None:
        self.ap = ap
        self.start_unix_us = start_unix_us
        digest = hashlib.sha256(f"uavtool-sitl:{sysid}:{instance}".encode()).digest()
        self.uid = int.from_bytes(digest[:8], "little")
        self.uid2 = list(digest[8:26])
        self.builders: dict[int, Callable[[], Any]] = {
            M.MAVLINK_MSG_ID_HEARTBEAT: self.heartbeat,
            M.MAVLINK_MSG_ID_SYS_STATUS: self.sys_status,
            M.MAVLINK_MSG_ID_SYSTEM_TIME: self.system_time,
            M.MAVLINK_MSG_ID_GPS_RAW_INT: self.gps_raw_int,
            M.MAVLINK_MSG_ID_ATTITUDE: self.attitude,
            M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: self.global_position_int,
            M.MAVLINK_MSG_ID_LOCAL_POSITION_NED: self.local_position_ned,
            M.MAVLINK_MSG_ID_VFR_HUD: self.vfr_hud,
            M.MAVLINK_MSG_ID_BATTERY_STATUS: self.battery_status,
            M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: self.extended_sys_state,
            M.MAVLINK_MSG_ID_MISSION_CURRENT: self.mission_current,
            M.MAVLINK_MSG_ID_HOME_POSITION: self.home_position,
            M.MAVLINK_MSG_ID_AUTOPILOT_VERSION: self.autopilot_version,
            M.MAVLINK_MSG_ID_GIMBAL_DEVICE_ATTITUDE_STATUS: self.gimbal_device_attitude_status,
            M.MAVLINK_MSG_ID_GIMBAL_MANAGER_STATUS: self.gimbal_manager_status,
            M.MAVLINK_MSG_ID_GIMBAL_MANAGER_INFORMATION: self.gimbal_manager_information,
            M.MAVLINK_MSG_ID_GIMBAL_DEVICE_INFORMATION: self.gimbal_device_information,
        }

    @property
    def boot_ms(self) -> int:
        return self.ap.now_ns // 1_000_000

    def build(self, msg_id: int) -> Any | None:
        builder = self.builders.get(msg_id)
        return builder() if builder is not None else None

    def heartbeat(self) -> Any:
        ap = self.ap
        base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        base |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        if ap.mode in _GUIDED_FLAG_MODES:
            base |= M.MAV_MODE_FLAG_GUIDED_ENABLED
        if ap.mode == Mode.AUTO:
            base |= M.MAV_MODE_FLAG_AUTO_ENABLED
        if ap.armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        if ap.crashed:  # for good: only a restart brings the vehicle back
            status = M.MAV_STATE_EMERGENCY
        elif ap.in_failsafe:
            status = M.MAV_STATE_CRITICAL
        elif ap.armed:
            status = M.MAV_STATE_ACTIVE
        else:
            status = M.MAV_STATE_STANDBY
        return M.MAVLink_heartbeat_message(
            M.MAV_TYPE_QUADROTOR, M.MAV_AUTOPILOT_ARDUPILOTMEGA, base, int(ap.mode), status, 3
        )

    def sys_status(self) -> Any:
        ap = self.ap
        enabled = _SENSORS if ap.armed else _SENSORS & ~M.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
        # After a crash the pre-arm checks fail (arming is refused until a restart).
        health = _SENSORS & ~M.MAV_SYS_STATUS_PREARM_CHECK if ap.crashed else _SENSORS
        present = _SENSORS
        # The fence as ArduCopter reports it: present when configured, enabled with
        # FENCE_ENABLE, healthy unless breached (MAVProxy says "fence breach" without it).
        fence = ap.fence
        if fence.present:
            present |= M.MAV_SYS_STATUS_GEOFENCE
        if fence.enabled:
            enabled |= M.MAV_SYS_STATUS_GEOFENCE
        if fence.healthy:
            health |= M.MAV_SYS_STATUS_GEOFENCE
        return M.MAVLink_sys_status_message(
            present,
            enabled,
            health,
            150,
            round(ap.battery.voltage() * 1000),
            round(ap.battery_current_a() * 100),
            ap.battery.remaining_pct(),
            0,
            0,
            0,
            0,
            0,
            0,
        )

    def system_time(self) -> Any:
        return M.MAVLink_system_time_message(
            self.start_unix_us + self.ap.now_ns // 1000, self.boot_ms
        )

    def _position(self) -> tuple[int, int, int, int]:
        ap = self.ap
        geo = ap.position_geo()
        noise = ap.params["SIM_GPS_NOISE"]
        lat_e7, lon_e7 = geo.lat_e7, geo.lon_e7
        if noise > 0:
            lat_e7 += round(ap.noise_rng.gauss(0.0, noise) / 0.011131884502145034)
            lon_e7 += round(ap.noise_rng.gauss(0.0, noise) / 0.011131884502145034)
        alt_rel = ap.alt_rel_m()
        baro = ap.params["SIM_BARO_RND"]
        if baro > 0:
            alt_rel += ap.noise_rng.gauss(0.0, baro)
        return lat_e7, lon_e7, round((ap.home.alt_amsl_m + alt_rel) * 1000), round(alt_rel * 1000)

    def gps_raw_int(self) -> Any:
        lat, lon, alt, _ = self._position()
        s = self.ap.state
        vel = math.hypot(s.vel_ned_ms[0], s.vel_ned_ms[1])
        cog = math.degrees(math.atan2(s.vel_ned_ms[1], s.vel_ned_ms[0])) % 360.0
        return M.MAVLink_gps_raw_int_message(
            self.ap.now_ns // 1000,
            M.GPS_FIX_TYPE_3D_FIX,
            lat,
            lon,
            alt,
            80,
            120,
            round(vel * 100),
            round(cog * 100) % 36000,
            16,
        )

    def attitude(self) -> Any:
        s = self.ap.state
        return M.MAVLink_attitude_message(
            self.boot_ms,
            math.radians(s.roll_deg),
            math.radians(s.pitch_deg),
            math.radians(wrap_180(s.yaw_deg)),
            0.0,
            0.0,
            math.radians(s.yaw_rate_dps),
        )

    def global_position_int(self) -> Any:
        lat, lon, alt, rel = self._position()
        s = self.ap.state
        vx, vy, vz = (round(v * 100) for v in s.vel_ned_ms)
        return M.MAVLink_global_position_int_message(
            self.boot_ms, lat, lon, alt, rel, vx, vy, vz, round(s.yaw_deg * 100) % 36000
        )

    def local_position_ned(self) -> Any:
        s = self.ap.state
        return M.MAVLink_local_position_ned_message(self.boot_ms, *s.pos_ned_m, *s.vel_ned_ms)

    def vfr_hud(self) -> Any:
        ap = self.ap
        s = ap.state
        speed = math.hypot(s.vel_ned_ms[0], s.vel_ned_ms[1])
        throttle = 0 if not ap.armed else min(100, round(100.0 * s.throttle))
        return M.MAVLink_vfr_hud_message(
            speed,
            speed,
            round(s.yaw_deg) % 360,
            throttle,
            ap.home.alt_amsl_m + ap.alt_rel_m(),
            -s.vel_ned_ms[2],
        )

    def battery_status(self) -> Any:
        ap = self.ap
        cell_mv = round(ap.battery.voltage() * 1000 / 3)
        cells = [cell_mv] * 3 + [65535] * 7
        return M.MAVLink_battery_status_message(
            0,
            M.MAV_BATTERY_FUNCTION_ALL,
            M.MAV_BATTERY_TYPE_LIPO,
            2500,
            cells,
            round(ap.battery_current_a() * 100),
            round(ap.battery.used_mah),
            round(ap.battery.used_wh * 36.0),  # hJ
            ap.battery.remaining_pct(),
        )

    def extended_sys_state(self) -> Any:
        return M.MAVLink_extended_sys_state_message(
            M.MAV_VTOL_STATE_UNDEFINED, self.ap.landed_state()
        )

    def mission_current(self) -> Any:
        mission = self.ap.mission
        total = max(len(mission.items) - 1, 0)
        if not mission.items:
            state = M.MISSION_STATE_NO_MISSION
        elif mission.running:
            state = M.MISSION_STATE_ACTIVE
        elif mission.current >= len(mission.items) - 1 and mission.current > 0:
            state = M.MISSION_STATE_COMPLETE
        else:
            state = M.MISSION_STATE_NOT_STARTED
        return M.MAVLink_mission_current_message(mission.current, total, state, 0)

    def home_position(self) -> Any:
        home = self.ap.home
        return M.MAVLink_home_position_message(
            home.lat_e7,
            home.lon_e7,
            round(home.alt_amsl_m * 1000),
            0.0,
            0.0,
            0.0,
            [1.0, 0.0, 0.0, 0.0],
            0.0,
            0.0,
            0.0,
            self.ap.now_ns // 1000,
        )

    def autopilot_version(self) -> Any:
        return M.MAVLink_autopilot_version_message(
            CAPABILITIES,
            FIRMWARE_VERSION,
            0,
            0,
            0,
            [0] * 8,
            [0] * 8,
            [0] * 8,
            0x1209,
            0x5741,
            self.uid,
            self.uid2,
        )

    def gimbal_device_attitude_status(self) -> Any | None:
        if not self.ap.mount.present:
            return None  # ArduPilot sends no gimbal message without a mount
        g = self.ap.gimbal
        q = list(gimbal_quaternion(g, self.ap.mount))
        flags = (
            M.GIMBAL_DEVICE_FLAGS_ROLL_LOCK
            | M.GIMBAL_DEVICE_FLAGS_PITCH_LOCK
            | M.GIMBAL_DEVICE_FLAGS_YAW_IN_VEHICLE_FRAME
        )
        # q is in the vehicle frame; delta_yaw is the vehicle's heading, relating it to earth.
        vehicle_yaw = math.radians(wrap_180(self.ap.state.yaw_deg))
        return M.MAVLink_gimbal_device_attitude_status_message(
            0, 0, self.boot_ms, flags, q, math.nan, math.nan, math.nan, 0, vehicle_yaw, math.nan, 1
        )

    def gimbal_manager_status(self) -> Any | None:
        if not self.ap.mount.present:
            return None  # ArduPilot sends no gimbal message without a mount
        flags = M.GIMBAL_MANAGER_FLAGS_ROLL_LOCK | M.GIMBAL_MANAGER_FLAGS_PITCH_LOCK
        if self.ap.gimbal.yaw_locked:
            flags |= M.GIMBAL_MANAGER_FLAGS_YAW_LOCK
        sysid = self.ap.gimbal_owner[0]
        compid = self.ap.gimbal_owner[1]
        return M.MAVLink_gimbal_manager_status_message(self.boot_ms, flags, 1, sysid, compid, 0, 0)

    def gimbal_manager_information(self) -> Any | None:
        if not self.ap.mount.present:
            return None  # ArduPilot sends no gimbal message without a mount
        cap = (
            M.GIMBAL_MANAGER_CAP_FLAGS_HAS_PITCH_AXIS
            | M.GIMBAL_MANAGER_CAP_FLAGS_HAS_PITCH_LOCK
            | M.GIMBAL_MANAGER_CAP_FLAGS_HAS_YAW_AXIS
            | M.GIMBAL_MANAGER_CAP_FLAGS_HAS_YAW_FOLLOW
            | M.GIMBAL_MANAGER_CAP_FLAGS_HAS_YAW_LOCK
        )
        return M.MAVLink_gimbal_manager_information_message(
            self.boot_ms, cap, 1, 0.0, 0.0, *self._gimbal_limits_rad()
        )

    def gimbal_device_information(self) -> Any | None:
        if not self.ap.mount.present:
            return None  # ArduPilot sends no gimbal message without a mount
        cap = (
            M.GIMBAL_DEVICE_CAP_FLAGS_HAS_PITCH_AXIS
            | M.GIMBAL_DEVICE_CAP_FLAGS_HAS_PITCH_LOCK
            | M.GIMBAL_DEVICE_CAP_FLAGS_HAS_YAW_AXIS
            | M.GIMBAL_DEVICE_CAP_FLAGS_HAS_YAW_FOLLOW
        )
        return M.MAVLink_gimbal_device_information_message(
            self.boot_ms, b"uavtool", b"sim gimbal", b"", 0, 0, 0, cap, 0, 0.0, 0.0,
            *self._gimbal_limits_rad(), 1,
        )  # fmt: skip

    def _gimbal_limits_rad(self) -> tuple[float, float, float, float]:
        """(pitch_min, pitch_max, yaw_min, yaw_max) of the mount, radians."""
        p = self.ap.params
        names = ("MNT1_PITCH_MIN", "MNT1_PITCH_MAX", "MNT1_YAW_MIN", "MNT1_YAW_MAX")
        low_pitch, high_pitch, low_yaw, high_yaw = (math.radians(p[n]) for n in names)
        return low_pitch, high_pitch, low_yaw, high_yaw


_NEVER_NS = 1 << 63


class Streams:
    """Per-link stream schedule: message id → (interval ns, next due ns)."""

    def __init__(self) -> None:
        self.interval_ns: dict[int, int] = {
            mid: round(_NS / hz) for mid, hz in DEFAULT_RATES_HZ.items()
        }
        self._next_ns: dict[int, int] = dict.fromkeys(self.interval_ns, 0)
        self._soonest_ns = 0  # no stream is due before this (most steps send nothing)

    def set_interval(self, msg_id: int, interval_us: float, now_ns: int) -> None:
        """MAV_CMD_SET_MESSAGE_INTERVAL semantics: -1 off, 0 default, else µs."""
        if interval_us < 0:
            self.interval_ns.pop(msg_id, None)
            self._next_ns.pop(msg_id, None)
            return
        if interval_us == 0:
            hz = DEFAULT_RATES_HZ.get(msg_id)
            if hz is None:
                self.interval_ns.pop(msg_id, None)
                self._next_ns.pop(msg_id, None)
                return
            self.interval_ns[msg_id] = round(_NS / hz)
        else:
            self.interval_ns[msg_id] = max(round(interval_us * 1000), 1_000_000)  # ≤ 1 kHz
        self._next_ns[msg_id] = now_ns
        self._soonest_ns = min(self._soonest_ns, now_ns)

    def set_rate_hz(self, msg_id: int, hz: float, now_ns: int) -> None:
        self.set_interval(msg_id, -1 if hz <= 0 else 1e6 / hz, now_ns)

    def due(self, now_ns: int) -> list[int]:
        if now_ns < self._soonest_ns:
            return []
        out = []
        soonest = _NEVER_NS
        next_ns = self._next_ns
        for mid, due_ns in next_ns.items():
            next_due = due_ns
            if now_ns >= due_ns:
                out.append(mid)
                interval = self.interval_ns[mid]
                # Keep the phase; if we fell far behind, restart from now rather than burst.
                following = due_ns + interval
                next_due = next_ns[mid] = following if following > now_ns else now_ns + interval
            if next_due < soonest:  # noqa: PLR1730 (no min() call: every stream, every step)
                soonest = next_due
        self._soonest_ns = soonest
        return out
