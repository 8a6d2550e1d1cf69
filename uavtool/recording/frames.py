"""``uavtool export REC --frames DIR``: a recording's camera frames as PNG files, each with a
JSON sidecar of its pose, plus the target picture when the recording holds one.

``DIR/frame_NNNN.png`` is the N-th ``/camera/image`` message (bytes as recorded: PNG is
lossless) and ``DIR/frame_NNNN.json`` what the recording says about it: capture time (vehicle
``time_boot_ms`` and ``log_time_ns``), camera pose in ENU metres around the recording's origin,
intrinsics, and tag / photo / trigger / ``pose_dt_ms`` where recorded. The poses come from
``/camera/frames`` (``uavtool record``) or from the mission's ``Photo`` observations
(``uavtool fly``). DIR appears only once complete.
"""

from __future__ import annotations

import json
import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.recording.errors import RecordingError, TopicNotFoundError
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import FRAMES, IMAGE, OBSERVATIONS, TARGET
from uavtool.recording.values import CompressedImage, JsonDocument

_SIDECAR_KEYS = (
    "frame_index",
    "tag",
    "photo",
    "trigger",
    "time_boot_ms",
    "pose",
    "intrinsics",
    "pose_time_boot_ms",
    "pose_dt_ms",
)


@dataclass(frozen=True, slots=True)
class FramesResult:
    frames: int
    with_pose: int
    target: bool


def export_frames(rec: str | Path, out_dir: str | Path, *, prefix: str = "") -> FramesResult:
    """Write every camera frame of ``rec`` into ``out_dir`` (which must not exist, or be
    empty): ``prefix`` names one vehicle of a fleet (``/uav2``). Raises `TopicNotFoundError`
    without frames, `RecordingError` if ``out_dir`` is not empty or cannot be written."""
    out_dir = Path(out_dir)
    if out_dir.exists() and (not out_dir.is_dir() or any(out_dir.iterdir())):
        raise RecordingError(out_dir, "exists and is not an empty folder: choose another")
    images: list[tuple[bytes, int]] = []
    poses: dict[int, dict[str, Any]] = {}
    target: bytes | None = None
    with RecordingReader(rec) as reader:
        topics = reader.topics()
        image = prefix + IMAGE
        if image not in topics:
            raise TopicNotFoundError(rec, image, topics)
        wanted = [t for t in (image, prefix + FRAMES, prefix + OBSERVATIONS, TARGET) if t in topics]
        for entry in reader.entries(wanted):
            value = entry.value
            if entry.topic == image and isinstance(value, CompressedImage):
                images.append((value.data, entry.log_time_ns))
            elif entry.topic == TARGET and isinstance(value, CompressedImage):
                target = target or value.data
            elif isinstance(value, JsonDocument) and value.payload.get("type") == "Photo":
                record = value.payload
                poses[int(record.get("frame_index", -1))] = {
                    k: record[k] for k in _SIDECAR_KEYS if k in record
                }
    partial = out_dir.with_name(f"{out_dir.name}.{os.getpid()}.partial")
    try:
        partial.mkdir(parents=True)
        for index, (png, log_time_ns) in enumerate(images):
            stem = partial / f"frame_{index:04d}"
            stem.with_suffix(".png").write_bytes(png)
            sidecar = {"frame_index": index, **poses.get(index, {}), "log_time_ns": log_time_ns}
            stem.with_suffix(".json").write_text(json.dumps(sidecar, indent=1) + "\n")
        if target is not None:
            (partial / "target.png").write_bytes(target)
        if out_dir.exists():
            out_dir.rmdir()  # empty, checked above
        partial.rename(out_dir)
    except OSError as exc:
        shutil.rmtree(partial, ignore_errors=True)
        raise RecordingError(out_dir, f"cannot write: {exc.strerror or exc}") from None
    with_pose = sum(1 for i in range(len(images)) if i in poses)
    return FramesResult(len(images), with_pose, target is not None)
