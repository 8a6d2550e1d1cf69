"""The pinhole camera model shared by the renderer, vision (3D model) and navigation.

Conventions
-----------
* World frame: local ENU metres around home (see :mod:`uavtool.geo`).
* Camera frame: OpenCV's — x right, y down, z forward (optical axis).
* Pixels: OpenCV/ROS convention, pixel ``(i, j)`` has its centre at ``u = i, v = j``;
  the principal point of a W×H image is ``((W-1)/2, (H-1)/2)``.
* The gimbal is stabilised: the camera's attitude is the vehicle heading plus the gimbal
  yaw, and the gimbal pitch (−90° nadir … 0° forward); vehicle roll and pitch do not tilt
  the image. At heading 0° and pitch −90° the image is a map: north up, east right.

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
    from north; ``pitch_deg`` is the gimbal pitch, −90 looking straight down.
    """

    pos_enu_m: tuple[float, float, float]
    heading_deg: float
    pitch_deg: float

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
        forward = (sh * cp, ch * cp, sp)
        right = (ch, -sh, 0.0)
        # down = forward × right
        down = (
            forward[1] * right[2] - forward[2] * right[1],
            forward[2] * right[0] - forward[0] * right[2],
            forward[0] * right[1] - forward[1] * right[0],
        )
        return right, down, forward

    def world_from_camera(self) -> FloatArray:
        """3×3 rotation whose columns are the camera's x (right), y (down), z (forward) in ENU."""
        return np.array(self.axes()).T.copy()

    def camera_from_world(self) -> FloatArray:
        """The inverse rotation (its transpose)."""
        return self.world_from_camera().T.copy()


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
