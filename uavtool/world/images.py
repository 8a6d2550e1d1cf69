"""Frames to files, and the labelled overview of a whole scene."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.fifo import reader_held
from uavtool.world.errors import SceneError
from uavtool.world.render import ImageRGB, render
from uavtool.world.scene import Scene

_OVERVIEW_HFOV_DEG = 60.0


def write_png(path: str | Path, rgb: ImageRGB) -> None:
    """Write an (H, W, 3) uint8 RGB image as a lossless PNG; raises SceneError on failure."""
    import cv2  # noqa: PLC0415  # keep `import uavtool.world` light

    target = Path(path)
    if target.suffix.lower() != ".png":
        raise SceneError(f"{target}: output must be a .png file")
    if not target.parent.is_dir():
        raise SceneError(f"{target}: directory {target.parent} does not exist")
    bgr = np.ascontiguousarray(rgb[:, :, ::-1])
    params = [cv2.IMWRITE_PNG_COMPRESSION, 3, cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_NONE]
    try:
        with reader_held(target):
            ok = cv2.imwrite(str(target), bgr, params)
    except cv2.error as exc:
        raise SceneError(f"{target}: cannot write PNG: {exc}") from exc
    if not ok:
        raise SceneError(f"{target}: cannot write PNG")


def overview_pose(scene: Scene, intrinsics: Intrinsics) -> CameraPose:
    """A nadir pose (north up) from which every building is in the frame."""
    xs = [x for b in scene.buildings for blk in b.blocks for x, _ in blk.footprint_enu_m]
    ys = [y for b in scene.buildings for blk in b.blocks for _, y in blk.footprint_enu_m]
    top = max(blk.top_m for b in scene.buildings for blk in b.blocks)
    half_x, half_y = (max(xs) - min(xs)) / 2.0, (max(ys) - min(ys)) / 2.0
    tan_h = math.tan(math.radians(intrinsics.hfov_deg) / 2.0)
    tan_v = math.tan(math.radians(intrinsics.vfov_deg) / 2.0)
    alt = top + 1.1 * max(half_x / tan_h, half_y / tan_v) + 2.0
    return CameraPose(((max(xs) + min(xs)) / 2.0, (max(ys) + min(ys)) / 2.0, alt), 0.0, -90.0)


def render_overview(scene: Scene, *, width_px: int = 960, height_px: int = 720) -> ImageRGB:
    """The whole scene from straight above, north up, each building labelled with its name."""
    import cv2  # noqa: PLC0415

    intrinsics = Intrinsics.from_hfov(
        width_px=width_px, height_px=height_px, hfov_deg=_OVERVIEW_HFOV_DEG
    )
    pose = overview_pose(scene, intrinsics)
    image = np.ascontiguousarray(render(scene, pose, intrinsics))
    font = cv2.FONT_HERSHEY_SIMPLEX
    for b in scene.buildings:
        pts = [(x, y, blk.top_m) for blk in b.blocks for x, y in blk.footprint_enu_m]
        centre = np.mean(np.array(pts), axis=0)[None, :]
        u, v, _ = project(centre, pose, intrinsics)[0]
        label = f"{b.name} (target)" if b.name == scene.target else b.name
        (tw, th), _ = cv2.getTextSize(label, font, 0.5, 1)
        org = (round(u - tw / 2), round(v + th / 2))
        cv2.putText(image, label, org, font, 0.5, (255, 255, 255), 3, cv2.LINE_AA)
        cv2.putText(image, label, org, font, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    return image
