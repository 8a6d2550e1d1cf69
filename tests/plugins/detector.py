"""A user's vision functions for the tests (the public API only)."""

from __future__ import annotations

import numpy as np

from uavtool.api import Detection, Frame


def red_roofs(frame: Frame) -> list[Detection]:
    """The red pixels' bounding box, their centre, and a triangle, by colour."""
    img = frame.image_rgb.astype(int)
    red = (img[:, :, 0] > 150) & (img[:, :, 1] < 80) & (img[:, :, 2] < 80)
    ys, xs = np.nonzero(red)
    if len(xs) < 20:
        return []
    box = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    centre = ((float(xs.mean()), float(ys.mean())),)
    triangle = ((box[0], box[1]), (box[2], box[1]), (box[0], box[3]))
    return [Detection("red roof", float(red.mean()), box, polygon_px=triangle, points_px=centre)]


def dicts(frame: Frame) -> list[dict[str, str]]:
    return [{"label": "not a Detection"}]


def raises(frame: Frame) -> list[Detection]:
    if frame.frame_index == 3:
        raise ValueError("model weights missing")
    return []


def vehicles(frame: Frame) -> list[Detection]:
    """One detection naming the vehicle that took the frame (a fleet's: its system id)."""
    return [Detection(f"vehicle {frame.vehicle}", 1.0, (0.0, 0.0, 1.0, 1.0))]
