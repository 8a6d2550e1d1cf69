"""What a user's vision function sees and returns (``uavtool replay --vision``): a recorded
photo with its pose, and detections in its pixels."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics


@dataclass(frozen=True, slots=True)
class Frame:
    """One recorded photo. ``image_rgb`` : (H, W, 3) uint8; ``pose`` in ENU metres around
    the vehicle's home; ``frame_index`` numbers the recording's (in a fleet's, the vehicle's)
    photos from 0."""

    frame_index: int
    tag: str
    time_boot_ms: int
    pose: CameraPose
    intrinsics: Intrinsics
    image_rgb: npt.NDArray[np.uint8]
    vehicle: int = 0
    """In a fleet's recording, the system id of the vehicle that took it (``frame_index`` and
    ``pose`` are that vehicle's); 0 in one vehicle's."""


@dataclass(frozen=True, slots=True)
class Detection:
    """What a vision function found in a frame, in pixels (x right, y down from the top left
    corner): a box, a polygon and/or points, with a label and a score, any of them optional."""

    label: str = ""
    score: float | None = None
    box_px: tuple[float, float, float, float] | None = None
    """(x_min, y_min, x_max, y_max)."""
    polygon_px: tuple[tuple[float, float], ...] = ()
    points_px: tuple[tuple[float, float], ...] = ()
