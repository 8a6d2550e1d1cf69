"""The MAVLink boundary of the runner: vehicle messages → :class:`Telemetry` observations,
mission commands → ArduPilot MAVLink (GUIDED position targets, COMMAND_LONG), and which
command each COMMAND_ACK answers."""

from __future__ import annotations

import math
from dataclasses import dataclass

from uavtool.camera import CameraPose, Quaternion, camera_from_attitude
from uavtool.geo import GeoPoint, enu_from_geo, geo_from_enu
from uavtool.link import VehicleLink
from uavtool.link.client import gimbal_camera_pose
from uavtool.mavlink.dialect import COPTER_MODE_NAMES, COPTER_MODES
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Arm, Command, GoTo, SetGimbal, SetMode, Takeoff, Telemetry

# SET_POSITION_TARGET: use the position (and yaw when given), ignore velocity, acceleration
# and yaw rate.
_POS_ONLY = (
    M.POSITION_TARGET_TYPEMASK_VX_IGNORE
    | M.POSITION_TARGET_TYPEMASK_VY_IGNORE
    | M.POSITION_TARGET_TYPEMASK_VZ_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AX_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AY_IGNORE
    | M.POSITION_TARGET_TYPEMASK_AZ_IGNORE
    | M.POSITION_TARGET_TYPEMASK_YAW_RATE_IGNORE
)


def telemetry(link: VehicleLink, commanded_gimbal: tuple[float, float]) -> Telemetry | None:
    """The vehicle's state now, in ENU around its home; None until home and position are
    known. A vehicle that reports no gimbal attitude is assumed to hold ``commanded_gimbal``."""
    s = link.state
    pos, home = s.position, s.home
    if pos is None or home is None or s.heartbeat is None:
        return None
    east, north, _ = enu_from_geo(home, GeoPoint(pos.lat / 1e7, pos.lon / 1e7, home.alt_amsl_m))
    heading = pos.hdg / 100.0 if pos.hdg != 65535 else _attitude_heading(link)
    hb = s.heartbeat
    armed = bool(hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)
    up = pos.relative_alt / 1000.0
    if s.extended is not None and s.extended.landed_state != M.MAV_LANDED_STATE_UNDEFINED:
        landed = s.extended.landed_state == M.MAV_LANDED_STATE_ON_GROUND
    else:
        landed = not armed and up < 1.0
    pitch = s.gimbal_pitch_deg
    yaw = s.gimbal_yaw_deg
    if pitch is None or yaw is None or math.isnan(pitch) or math.isnan(yaw):
        pitch, yaw = commanded_gimbal
    battery = s.sys_status.battery_remaining if s.sys_status is not None else -1
    return Telemetry(
        time_boot_ms=int(pos.time_boot_ms),
        pos_enu_m=(east, north, up),
        vel_enu_m_s=(pos.vy / 100.0, pos.vx / 100.0, -pos.vz / 100.0),
        heading_deg=heading % 360.0,
        mode=COPTER_MODE_NAMES.get(hb.custom_mode, f"MODE{hb.custom_mode}"),
        armed=armed,
        landed=landed,
        gimbal_pitch_deg=float(pitch),
        gimbal_yaw_deg=float(yaw),
        battery_pct=int(battery),
    )


def _attitude_heading(link: VehicleLink) -> float:
    att = link.state.attitude
    return math.degrees(att.yaw) % 360.0 if att is not None else 0.0


def camera_pose(t: Telemetry) -> CameraPose:
    """The camera's pose as the telemetry reports it (ENU around the vehicle's home)."""
    return CameraPose.from_vehicle(
        pos_enu_m=t.pos_enu_m,
        vehicle_heading_deg=t.heading_deg,
        gimbal_pitch_deg=t.gimbal_pitch_deg,
        gimbal_yaw_deg=t.gimbal_yaw_deg,
    )


NADIR: Quaternion = (math.sqrt(0.5), 0.0, -math.sqrt(0.5), 0.0)
"""A camera fixed to the frame looking straight down: pitch −90° in the body frame."""


def photo_pose(link: VehicleLink, t: Telemetry, *, fixed_down: bool = False) -> CameraPose:
    """The camera's pose at a photo from the whole attitude: the gimbal's last quaternion
    composed with the vehicle's heading; for a camera ``fixed_down`` to the frame, the
    vehicle's roll and pitch tilt it too. Without a gimbal report, the commanded angles."""
    s = link.state
    if fixed_down:
        att = s.attitude
        roll, pitch = (math.degrees(att.roll), math.degrees(att.pitch)) if att else (0.0, 0.0)
        return camera_from_attitude(
            t.pos_enu_m,
            vehicle_heading_deg=t.heading_deg,
            gimbal_q=NADIR,
            yaw_in_vehicle_frame=True,
            vehicle_roll_deg=roll,
            vehicle_pitch_deg=pitch,
            stabilised=False,
        )
    if s.gimbal is not None:
        pose = gimbal_camera_pose(
            s.gimbal, pos_enu_m=t.pos_enu_m, vehicle_heading_deg=t.heading_deg
        )
        if pose is not None:
            return pose
    return camera_pose(t)


@dataclass(frozen=True, slots=True)
class Sent:
    """A command on the wire: the MAVLink command number its ACK will carry (0: none)."""

    mav_cmd: int


def send_command(link: VehicleLink, cmd: Command, home: GeoPoint) -> Sent:
    """Send a mission command the way ArduCopter takes it."""
    if isinstance(cmd, SetMode):
        number = COPTER_MODES.get(cmd.mode)
        if number is None:
            raise ValueError(f"unknown ArduCopter mode {cmd.mode!r}")
        link.command_long(M.MAV_CMD_DO_SET_MODE, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, number)
        return Sent(M.MAV_CMD_DO_SET_MODE)
    if isinstance(cmd, Arm):
        link.command_long(M.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
        return Sent(M.MAV_CMD_COMPONENT_ARM_DISARM)
    if isinstance(cmd, Takeoff):
        link.command_long(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, cmd.alt_m)
        return Sent(M.MAV_CMD_NAV_TAKEOFF)
    if isinstance(cmd, SetGimbal):
        link.command_long(
            M.MAV_CMD_DO_MOUNT_CONTROL,
            cmd.pitch_deg,
            0.0,
            cmd.yaw_deg,
            0,
            0,
            0,
            M.MAV_MOUNT_MODE_MAVLINK_TARGETING,
        )
        return Sent(M.MAV_CMD_DO_MOUNT_CONTROL)
    if isinstance(cmd, GoTo):
        x, y, z = cmd.pos_enu_m
        target = geo_from_enu(home, x, y, 0.0)
        mask = _POS_ONLY | (M.POSITION_TARGET_TYPEMASK_YAW_IGNORE if cmd.heading_deg is None else 0)
        yaw = 0.0 if cmd.heading_deg is None else math.radians(cmd.heading_deg)
        link.send(
            M.MAVLink_set_position_target_global_int_message(
                0,
                link.target_system,
                link.target_component,
                M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                mask,
                target.lat_e7,
                target.lon_e7,
                z,
                0,
                0,
                0,
                0,
                0,
                0,
                yaw,
                0,
            )
        )
        return Sent(0)  # position targets have no ACK
    raise TypeError(f"not a vehicle command: {cmd!r}")


RESULT_NAMES = {
    v: k for k, v in vars(M).items() if k.startswith("MAV_RESULT_") and isinstance(v, int)
}
COMMAND_NAMES = {
    v: k.removeprefix("MAV_CMD_")
    for k, v in vars(M).items()
    if k.startswith("MAV_CMD_") and isinstance(v, int)
}
