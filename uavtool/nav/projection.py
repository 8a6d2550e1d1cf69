"""Pixels to ground: where a camera pixel's ray meets a horizontal plane.

The rotation comes from :meth:`uavtool.camera.CameraPose.axes` (``math`` scalars), so the
decision math never goes through numpy (see DESIGN, determinism).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.nav.errors import NavError

Vec3 = tuple[float, float, float]


def ground_point(
    u_px: float,
    v_px: float,
    pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    plane_z_m: float = 0.0,
) -> tuple[float, float]:
    """ENU ``(east_m, north_m)`` where the ray through pixel ``(u_px, v_px)`` meets z = plane_z_m.

    Pixels follow OpenCV (u right, v down, pixel centres at integers). Raises NavError when
    the ray does not go down to the plane (at or above the horizon, or the camera not above
    the plane).
    """
    u, v = float(u_px), float(v_px)
    if not (math.isfinite(u) and math.isfinite(v)):
        raise NavError(f"pixel ({u_px}, {v_px}) is not finite")
    right, down, forward = pose.axes()
    x = (u - intrinsics.cx_px) / intrinsics.fx_px
    y = (v - intrinsics.cy_px) / intrinsics.fy_px
    d = tuple(right[i] * x + down[i] * y + forward[i] for i in range(3))
    cam_x, cam_y, cam_z = (float(c) for c in pose.pos_enu_m)
    height_m = cam_z - plane_z_m
    if not height_m > 0.0:
        raise NavError(
            f"camera at z={cam_z:g} m is not above the plane z={plane_z_m:g} m: "
            f"pixel ({u:g}, {v:g}) cannot be placed on it"
        )
    if not d[2] < 0.0:
        elevation_deg = math.degrees(math.atan2(d[2], math.sqrt(d[0] * d[0] + d[1] * d[1])))
        raise NavError(
            f"pixel ({u:g}, {v:g}) looks {elevation_deg:.2f}° above the horizon "
            f"(gimbal pitch {pose.pitch_deg:g}°): its ray never reaches the ground"
        )
    t = height_m / -d[2]
    return (cam_x + t * d[0], cam_y + t * d[1])


def frame_corners_px(intrinsics: Intrinsics) -> list[tuple[float, float]]:
    """The corner pixels of a frame, clockwise on screen from the top left."""
    w, h = intrinsics.width_px - 1.0, intrinsics.height_px - 1.0
    return [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]


def frame_on_plane(
    pose: CameraPose, intrinsics: Intrinsics, *, plane_z_m: float = 0.0
) -> tuple[tuple[float, float], ...]:
    """Where the frame's corners (:func:`frame_corners_px`) meet z = ``plane_z_m``: what a
    photo looking down shows of that plane. NavError as :func:`ground_point`."""
    return tuple(
        ground_point(u, v, pose, intrinsics, plane_z_m=plane_z_m)
        for u, v in frame_corners_px(intrinsics)
    )


def poi_offset(
    u_px: float,
    v_px: float,
    *,
    alt_m: float,
    heading_deg: float,
    intrinsics: Intrinsics,
    gimbal_pitch_deg: float = -90.0,
) -> tuple[float, float]:
    """Metres ``(north_m, east_m)`` (north first) from the vehicle to the ground seen at a pixel.

    The paper's ``calcMoveToTargetHorizont``: the pixel's offset from the image centre,
    scaled by the altitude above ground and the angles of view (a pinhole's
    ``fx = (W/2) / tan(hfov/2)``), turned by the compass heading of the camera. Raises
    NavError for ``alt_m ≤ 0`` or a pixel whose ray misses the ground.
    """
    if not alt_m > 0.0:
        raise NavError(f"altitude above ground must be positive to place a pixel, got {alt_m}")
    pose = CameraPose((0.0, 0.0, float(alt_m)), float(heading_deg), float(gimbal_pitch_deg))
    east_m, north_m = ground_point(u_px, v_px, pose, intrinsics)
    return (north_m, east_m)


def ground_polygon(
    ring_px: npt.ArrayLike | Sequence[Sequence[float]],
    pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    plane_z_m: float = 0.0,
) -> tuple[tuple[float, float], ...]:
    """Each vertex of ``ring_px`` ((n, 2) float pixels) projected with :func:`ground_point`.

    Returns n ``(east_m, north_m)`` vertices in the same order; raises NavError if any
    vertex misses the plane.
    """
    ring = np.asarray(ring_px, dtype=np.float64)
    if ring.ndim != 2 or ring.shape[1] != 2:
        raise NavError(f"a pixel ring must have shape (n, 2), got {ring.shape}")
    rows: list[list[float]] = ring.tolist()
    return tuple(ground_point(u, v, pose, intrinsics, plane_z_m=plane_z_m) for u, v in rows)
