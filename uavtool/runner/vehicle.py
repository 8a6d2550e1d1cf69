"""The MAVLink boundary of the runner, inbound: vehicle messages → :class:`Telemetry`
observations and camera poses. (Outbound, mission commands go on the wire through the
vehicle's :class:`~uavtool.autopilot.Autopilot`.)"""

from __future__ import annotations

import math

from uavtool.autopilot import Autopilot
from uavtool.camera import CameraPose, Quaternion, camera_from_attitude
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.link import VehicleLink
from uavtool.link.client import gimbal_camera_pose
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import Telemetry


def telemetry(
    link: VehicleLink, commanded_gimbal: tuple[float, float], autopilot: Autopilot
) -> Telemetry | None:
    """The vehicle's state now, in ENU around its home, its mode in the mission's vocabulary;
    None until home and position are known. A vehicle that reports no gimbal attitude is
    assumed to hold ``commanded_gimbal``."""
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
        mode=autopilot.mission_mode(hb),
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
