"""Your vision on recorded frames: a user's function over every photo of a recording, its
detections written to a new recording beside the original's channels.

The function is named on the command line (``module:function``) and is called once per photo
with a :class:`Frame` (image, camera pose, intrinsics, vehicle time); it returns
:class:`Detection` values. The new recording holds every message of the original, unchanged,
plus the detections twice: ``/vision/annotations`` (``foxglove.ImageAnnotations``, stamped
with the photo's time, so Foxglove's and Lichtblick's image panels draw them on the frame
they came from) and ``/vision/detections`` (JSON, as returned, for Rerun and for tables).
"""

from __future__ import annotations

import importlib
import math
import re
import traceback
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.errors import FailureError, InputError
from uavtool.images import png_decode
from uavtool.mission.codec import decode_observation
from uavtool.mission.observations import Photo
from uavtool.plugins import code_dir
from uavtool.recording import CompressedImage, JsonDocument, RecordingReader
from uavtool.recording.annotations import (
    DETECTIONS,
    DETECTIONS_SCHEMA,
    copy_with_detections,
)
from uavtool.recording.fleet import split_topic, vehicle_prefix
from uavtool.recording.topics import FRAMES, IMAGE, OBSERVATIONS
from uavtool.vision.detection import Detection, Frame

_TARGET = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_]\w*$")
_MAX_DETECTIONS = 10_000
"""Per frame: more is a bug in the function, not a scene."""
_MAX_POINTS = 100_000


VisionFunction = Callable[[Frame], Iterable[Detection]]


@dataclass(frozen=True, slots=True)
class VisionRun:
    frames: int
    detections: int
    out: Path


class VisionCodeError(FailureError):
    """The user's vision function raised or returned something else than detections."""


def load_function(spec: str) -> VisionFunction:
    """The function ``module:function`` names (from the command line: a recording never names
    code). PluginError-like one-line InputError when it cannot be loaded."""
    if not _TARGET.match(spec):
        raise InputError(f"--vision {spec!r}: expected module:function")
    code_dir()
    module_name, _, name = spec.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"--vision {spec}: cannot import {module_name}: {exc}") from None
    except Exception as exc:
        raise InputError(f"--vision {spec}: importing {module_name} failed: {exc!r}") from None
    function = getattr(module, name, None)
    if not callable(function):
        raise InputError(f"--vision {spec}: {module_name} has no function {name}")
    return function  # type: ignore[no-any-return]


def frames(path: Path) -> Iterator[tuple[Frame, int]]:
    """Every photo of a recording (``uavtool fly`` or ``uavtool record``) with its log time:
    in a fleet's, each vehicle's (``Frame.vehicle``), in log-time order."""
    with RecordingReader(path) as reader:
        topics = set(reader.topics())
        vehicles = sorted({k for k, rest in map(split_topic, topics) if k and rest == IMAGE})
        if not vehicles:
            yield from _photos(reader, path, topics, 0)
            return
        each = [list(_photos(reader, path, topics, k)) for k in vehicles]
    yield from sorted(
        (photo for photos in each for photo in photos), key=lambda p: (p[1], p[0].vehicle)
    )


def _photos(
    reader: RecordingReader, path: Path, topics: set[str], vehicle: int
) -> Iterator[tuple[Frame, int]]:
    """The photos of one vehicle (``vehicle`` 0: the only one, topics without a prefix)."""
    prefix = vehicle_prefix(vehicle) if vehicle else ""
    image_topic = prefix + IMAGE
    source = next((prefix + t for t in (OBSERVATIONS, FRAMES) if prefix + t in topics), None)
    if source is None or image_topic not in topics:
        raise InputError(
            f"{path}: no photos ({image_topic} with {prefix + OBSERVATIONS} or "
            f"{prefix + FRAMES}): record a flight with `uavtool fly` or `uavtool record`"
        )
    images: list[bytes] = []
    for entry in reader.entries([image_topic, source]):
        value = entry.value
        if entry.topic == image_topic and isinstance(value, CompressedImage):
            images.append(value.data)
        elif isinstance(value, JsonDocument) and value.payload.get("type") == "Photo":
            data = dict(value.payload)
            index = data.get("frame_index")
            if type(index) is not int or not 0 <= index < len(images):
                raise InputError(
                    f"{path}: {prefix}photo frame {index!r:.20} has no image before it"
                )
            image = png_decode(images[index], where=f"{path}: {prefix}frame {index}")
            photo = decode_observation(data, image)
            assert isinstance(photo, Photo)
            frame = Frame(
                photo.frame_index,
                photo.tag,
                photo.time_boot_ms,
                photo.pose,
                photo.intrinsics,
                image,
                vehicle,
            )
            yield frame, entry.log_time_ns


def run_vision(path: Path, out: Path, spec: str, function: VisionFunction) -> VisionRun:
    """Call ``function`` on every photo of ``path`` and write ``out``: ``path``'s messages and
    the detections. ``out`` appears only when whole; nothing is written if the function fails."""
    found: list[tuple[int, dict[str, Any]]] = []
    prefixes: list[str] = []
    count = 0
    for frame, t_ns in frames(path):
        prefixes.append(vehicle_prefix(frame.vehicle) if frame.vehicle else "")
        detections = _call(function, frame, spec)
        count += len(detections)
        found.append(
            (
                t_ns,
                {
                    "frame_index": frame.frame_index,
                    "tag": frame.tag,
                    "time_boot_ms": frame.time_boot_ms,
                    "width_px": frame.intrinsics.width_px,
                    "height_px": frame.intrinsics.height_px,
                    "detections": [_json(d) for d in detections],
                },
            )
        )
    record = {"function": spec, "source": path.name}
    copy_with_detections(path, out, found, record, prefixes=prefixes if any(prefixes) else ())
    return VisionRun(len(found), count, out)


def _call(function: VisionFunction, frame: Frame, spec: str) -> list[Detection]:
    where = f"--vision {spec} on frame {frame.frame_index} ({frame.tag})"
    try:
        result = list(function(frame))
    except Exception as exc:
        last = traceback.extract_tb(exc.__traceback__)[-1]
        raise VisionCodeError(
            f"{where} raised {type(exc).__name__}: {exc} (at {Path(last.filename).name}:"
            f"{last.lineno}); nothing written"
        ) from exc
    if len(result) > _MAX_DETECTIONS:
        raise VisionCodeError(f"{where}: {len(result)} detections, more than {_MAX_DETECTIONS}")
    for item in result:
        if not isinstance(item, Detection):
            raise VisionCodeError(
                f"{where} returned a {type(item).__name__}, expected uavtool.api.Detection "
                "values; nothing written"
            )
        _check(item, where)
    return result


def _check(d: Detection, where: str) -> None:
    numbers = [*(d.box_px or ()), *(v for p in (*d.polygon_px, *d.points_px) for v in p)]
    if d.score is not None:
        numbers.append(d.score)
    if len(numbers) > _MAX_POINTS or not all(
        isinstance(v, (int, float)) and math.isfinite(v) for v in numbers
    ):
        raise VisionCodeError(f"{where}: a detection holds a value that is no finite number")


def _json(d: Detection) -> dict[str, Any]:
    out: dict[str, Any] = {"label": d.label}
    if d.score is not None:
        out["score"] = float(d.score)
    if d.box_px is not None:
        out["box_px"] = [float(v) for v in d.box_px]
    if d.polygon_px:
        out["polygon_px"] = [[float(x), float(y)] for x, y in d.polygon_px]
    if d.points_px:
        out["points_px"] = [[float(x), float(y)] for x, y in d.points_px]
    return out


__all__ = ["DETECTIONS", "DETECTIONS_SCHEMA", "Detection", "Frame", "run_vision"]
