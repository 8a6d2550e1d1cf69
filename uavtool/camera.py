"""The pinhole camera model shared by the renderer, vision (3D model) and navigation.

Conventions
-----------
* World frame: local ENU metres around home (see :mod:`uavtool.geo`).
* Camera frame: OpenCV's — x right, y down, z forward (optical axis).
* Pixels: OpenCV/ROS convention, pixel ``(i, j)`` has its centre at ``u = i, v = j``;
  the principal point of a W×H image is ``((W-1)/2, (H-1)/2)``.
* A camera's attitude is heading, roll, pitch in a gimbal's own order: the heading turns
  about the vertical, the roll tilts the heading's horizontal right axis, the pitch turns
  about that rolled right axis (−90° nadir … 0° forward). That order is singular only at
  ±90° roll, never at the nadir, so a camera looking straight down keeps the heading its
  image shows. At heading 0°, roll 0° and pitch −90° the image is a map: north up, east right.
* :func:`camera_from_attitude` composes a vehicle's attitude and a gimbal's quaternion
  (MAVLink's, in its vehicle or earth frame) into that attitude through rotation matrices,
  never through Euler angles.

Only ``math`` trigonometry and IEEE arithmetic are used to build matrices, so a pose gives
bit-identical matrices on every machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.errors import InputError

FloatArray = npt.NDArray[np.float64]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Intrinsics:
    """Pinhole intrinsics with square pixels and no distortion."""

    width_px: int
    height_px: int
    fx_px: float
    fy_px: float
    cx_px: float
    cy_px: float

    @classmethod
    def from_hfov(
        cls, *, width_px: int = 640, height_px: int = 480, hfov_deg: float = 60.0
    ) -> Intrinsics:
        """Intrinsics of a ``width_px``×``height_px`` camera with horizontal FOV ``hfov_deg``."""
        if width_px <= 0 or height_px <= 0:
            raise InputError(f"camera size must be positive, got {width_px}x{height_px}")
        if not 1.0 <= hfov_deg <= 170.0:
            raise InputError(f"camera horizontal FOV must be in [1, 170] degrees, got {hfov_deg}")
        f_px = (width_px / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        return cls(width_px, height_px, f_px, f_px, (width_px - 1) / 2.0, (height_px - 1) / 2.0)

    @property
    def hfov_deg(self) -> float:
        return math.degrees(2.0 * math.atan((self.width_px / 2.0) / self.fx_px))

    @property
    def vfov_deg(self) -> float:
        return math.degrees(2.0 * math.atan((self.height_px / 2.0) / self.fy_px))

    @property
    def k(self) -> FloatArray:
        """The 3×3 camera matrix K."""
        return np.array(
            [[self.fx_px, 0.0, self.cx_px], [0.0, self.fy_px, self.cy_px], [0.0, 0.0, 1.0]]
        )


@dataclass(frozen=True, slots=True)
class CameraPose:
    """Where the camera is and where it looks, in world ENU.

    ``heading_deg`` is the camera's own heading (vehicle heading + gimbal yaw), clockwise
    from north; ``pitch_deg`` is the gimbal pitch, −90 looking straight down; ``roll_deg``
    tilts the camera's right side down (a stabilised gimbal's residual, a few tenths).
    """

    pos_enu_m: tuple[float, float, float]
    heading_deg: float
    pitch_deg: float
    roll_deg: float = 0.0

    @classmethod
    def from_vehicle(
        cls,
        *,
        pos_enu_m: tuple[float, float, float],
        vehicle_heading_deg: float,
        gimbal_pitch_deg: float,
        gimbal_yaw_deg: float = 0.0,
    ) -> CameraPose:
        """The pose of a stabilised gimbal camera on a vehicle."""
        return cls(pos_enu_m, vehicle_heading_deg + gimbal_yaw_deg, gimbal_pitch_deg)

    def axes(self) -> tuple[Vec3, Vec3, Vec3]:
        """The camera's x (right), y (down), z (forward) unit axes in ENU, from ``math``
        scalars only (decision math in nav uses these, never numpy)."""
        h = math.radians(self.heading_deg)
        p = math.radians(self.pitch_deg)
        sh, ch, sp, cp = math.sin(h), math.cos(h), math.sin(p), math.cos(p)
        if self.roll_deg == 0.0:
            forward = (sh * cp, ch * cp, sp)
            right = (ch, -sh, 0.0)
        else:
            r = math.radians(self.roll_deg)
            sr, cr = math.sin(r), math.cos(r)
            # heading's forward (sh, ch, 0) and right (ch, -sh, 0); the roll tilts right and up
            right = (cr * ch, -cr * sh, -sr)
            up = (sr * ch, -sr * sh, cr)
            forward = (cp * sh + sp * up[0], cp * ch + sp * up[1], sp * up[2])
        # down = forward × right
        down = (
            forward[1] * right[2] - forward[2] * right[1],
            forward[2] * right[0] - forward[0] * right[2],
            forward[0] * right[1] - forward[1] * right[0],
        )
        return right, down, forward

    @classmethod
    def from_axes(cls, pos_enu_m: Vec3, right: Vec3, forward: Vec3) -> CameraPose:
        """The pose whose :meth:`axes` are ``right`` and ``forward`` (unit, orthogonal, ENU).
        Well conditioned everywhere but at ±90° roll; the heading is wrapped to [0, 360)."""
        horizontal = math.hypot(right[0], right[1])
        roll = math.atan2(-right[2], horizontal)
        heading = math.atan2(-right[1], right[0])
        sh, ch = math.sin(heading), math.cos(heading)
        sr, cr = math.sin(roll), math.cos(roll)
        up = (sr * ch, -sr * sh, cr)  # the rolled frame's up
        pitch = math.atan2(
            forward[0] * up[0] + forward[1] * up[1] + forward[2] * up[2],
            forward[0] * sh + forward[1] * ch,
        )
        heading_deg = math.degrees(heading) % 360.0
        return cls(
            pos_enu_m,
            0.0 if heading_deg == 360.0 else heading_deg,
            math.degrees(pitch),
            math.degrees(roll) + 0.0,  # never -0.0
        )

    def world_from_camera(self) -> FloatArray:
        """3×3 rotation whose columns are the camera's x (right), y (down), z (forward) in ENU."""
        return np.array(self.axes()).T.copy()

    def camera_from_world(self) -> FloatArray:
        """The inverse rotation (its transpose)."""
        return self.world_from_camera().T.copy()


Quaternion = tuple[float, float, float, float]
"""(w, x, y, z), MAVLink's order and frame: x north (or forward), y east (or right), z down."""


def camera_from_attitude(
    pos_enu_m: Vec3,
    *,
    vehicle_heading_deg: float,
    gimbal_q: Quaternion,
    yaw_in_vehicle_frame: bool,
    vehicle_roll_deg: float = 0.0,
    vehicle_pitch_deg: float = 0.0,
    stabilised: bool = True,
) -> CameraPose:
    """The camera's pose from the vehicle's attitude and its gimbal's quaternion (the
    camera looks along the gimbal's x axis, its image right along y).

    ``yaw_in_vehicle_frame``: the quaternion's yaw is relative to the nose (MAVLink's
    ``GIMBAL_DEVICE_FLAGS_YAW_IN_VEHICLE_FRAME``), else to north. ``stabilised``: its roll
    and pitch are relative to the horizon (``ROLL_LOCK``/``PITCH_LOCK``, any stabilised
    gimbal), else to the vehicle's body, whose roll and pitch then tilt the camera (a camera
    fixed to the frame: the identity quaternion with pitch −90° looks straight down).
    Raises InputError for a quaternion that is not finite or is zero."""
    w, x, y, z = gimbal_q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if not math.isfinite(n) or n < 1e-6:
        raise InputError(f"gimbal quaternion {gimbal_q} is not a rotation")
    w, x, y, z = w / n, x / n, y / n, z / n
    gimbal = (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )
    if not stabilised:
        body = _rotation_ned(vehicle_heading_deg, vehicle_pitch_deg, vehicle_roll_deg)
        world = _matmul(body, gimbal)
    elif yaw_in_vehicle_frame:
        world = _matmul(_rotation_ned(vehicle_heading_deg, 0.0, 0.0), gimbal)
    else:
        world = gimbal
    # columns: the gimbal's x (forward) and y (right) in NED; ENU is (east, north, up)
    forward = (world[1][0], world[0][0], -world[2][0])
    right = (world[1][1], world[0][1], -world[2][1])
    return CameraPose.from_axes(pos_enu_m, right, forward)


Matrix3 = tuple[Vec3, Vec3, Vec3]


def _rotation_ned(yaw_deg: float, pitch_deg: float, roll_deg: float) -> Matrix3:
    """NED-from-body rotation of a vehicle's (yaw, pitch, roll): aerospace Z-Y-X order."""
    cy, sy = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    cp, sp = math.cos(math.radians(pitch_deg)), math.sin(math.radians(pitch_deg))
    cr, sr = math.cos(math.radians(roll_deg)), math.sin(math.radians(roll_deg))
    return (
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    )


def _matmul(a: Matrix3, b: Matrix3) -> Matrix3:
    rows = [
        tuple(a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] for j in range(3))
        for i in range(3)
    ]
    return (
        (rows[0][0], rows[0][1], rows[0][2]),
        (rows[1][0], rows[1][1], rows[1][2]),
        (rows[2][0], rows[2][1], rows[2][2]),
    )


def project(points_enu_m: FloatArray, pose: CameraPose, intrinsics: Intrinsics) -> FloatArray:
    """Project world points to pixels.

    points_enu_m : (n, 3) float — world ENU metres.
    Returns (n, 3) float: ``u_px, v_px, depth_m`` (depth along the optical axis; points
    behind the camera have depth ≤ 0 and meaningless pixels).
    """
    rel = np.asarray(points_enu_m, dtype=np.float64) - np.asarray(pose.pos_enu_m, dtype=np.float64)
    cam = rel @ pose.world_from_camera()  # (n,3) in camera frame: x right, y down, z forward
    z = cam[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = intrinsics.fx_px * cam[:, 0] / z + intrinsics.cx_px
        v = intrinsics.fy_px * cam[:, 1] / z + intrinsics.cy_px
    return np.stack([u, v, z], axis=1)


def pixel_ray(u_px: float, v_px: float, pose: CameraPose, intrinsics: Intrinsics) -> FloatArray:
    """Unit direction (ENU) of the ray through pixel ``(u_px, v_px)``."""
    d_cam = np.array(
        [
            (u_px - intrinsics.cx_px) / intrinsics.fx_px,
            (v_px - intrinsics.cy_px) / intrinsics.fy_px,
            1.0,
        ]
    )
    d: FloatArray = pose.world_from_camera() @ d_cam
    return d / math.sqrt(float(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]))
