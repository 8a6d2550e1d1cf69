"""JSON (de)serialisation of shapes and of the poses file the model command reads.

Shapes file (``uavtool.shapes``, version 1)::

    {"format": "uavtool.shapes", "version": 1, "width_px": 640, "height_px": 480,
     "shapes": [{"colour_rgb": [210, 40, 40], "polygon_px": [[u, v], ...],
                 "holes_px": [[[u, v], ...]], "area_px": 1234.5,
                 "centroid_px": [u, v], "cut_by_border": false}]}

Floats are written with Python's shortest round-trip repr, so reading gives back the
exact same values.

Poses file (``--poses`` of ``uavtool vision model``): one entry per photo, ``top``,
``front`` and ``right``::

    {"top":   {"pos_enu_m": [10, -8, 20], "heading_deg": 0, "pitch_deg": -90,
               "intrinsics": {"width_px": 640, "height_px": 480, "hfov_deg": 60}},
     "front": {...}, "right": {...}, "ground_z_m": 0.0}

``intrinsics`` holds either ``hfov_deg`` (square pixels, centred principal point) or
``fx_px``, ``fy_px``, ``cx_px``, ``cy_px``; ``ground_z_m`` is optional.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from uavtool.camera import CameraPose, Intrinsics
from uavtool.errors import InputError
from uavtool.vision.errors import ShapeFileError
from uavtool.vision.shapes import FloatArray, Shape

SHAPES_FORMAT = "uavtool.shapes"
SHAPES_VERSION = 1
VIEW_NAMES = ("top", "front", "right")


def shapes_to_json(shapes: tuple[Shape, ...], *, width_px: int, height_px: int) -> str:
    """The shapes of one frame as a JSON document."""
    doc = {
        "format": SHAPES_FORMAT,
        "version": SHAPES_VERSION,
        "width_px": width_px,
        "height_px": height_px,
        "shapes": [
            {
                "colour_rgb": list(s.colour_rgb),
                "polygon_px": s.polygon_px.tolist(),
                "holes_px": [h.tolist() for h in s.holes_px],
                "area_px": s.area_px,
                "centroid_px": list(s.centroid_px),
                "cut_by_border": s.cut_by_border,
                "detail_px": s.detail_px,
                "left_out_px": s.left_out_px,
            }
            for s in shapes
        ],
    }
    return json.dumps(doc, indent=1)


def shapes_from_json(text: str, *, source: str = "<shapes>") -> tuple[Shape, ...]:
    """Shapes read back from :func:`shapes_to_json`; raises :class:`ShapeFileError`."""
    doc = _load(text, source)
    if doc.get("format") != SHAPES_FORMAT:
        raise ShapeFileError(f"{source}: not a {SHAPES_FORMAT} file (format={doc.get('format')!r})")
    if doc.get("version") != SHAPES_VERSION:
        raise ShapeFileError(f"{source}: unsupported version {doc.get('version')!r}")
    items = doc.get("shapes")
    if not isinstance(items, list):
        raise ShapeFileError(f"{source}: shapes: expected a list")
    out: list[Shape] = []
    for i, item in enumerate(items):
        where = f"{source}: shapes[{i}]"
        try:
            colour = tuple(int(c) for c in item["colour_rgb"])
            if len(colour) != 3:
                raise ValueError("colour_rgb needs 3 values")
            polygon = _ring(item["polygon_px"], f"{where}.polygon_px")
            holes = tuple(
                _ring(h, f"{where}.holes_px[{k}]") for k, h in enumerate(item["holes_px"])
            )
            centroid = (float(item["centroid_px"][0]), float(item["centroid_px"][1]))
            out.append(
                Shape(
                    (colour[0], colour[1], colour[2]),
                    polygon,
                    holes,
                    float(item["area_px"]),
                    centroid,
                    bool(item["cut_by_border"]),
                    _detail(item.get("detail_px", 0.0), f"{where}.detail_px"),
                    _detail(item.get("left_out_px", 0.0), f"{where}.left_out_px"),
                )
            )
        except ShapeFileError:
            raise
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise ShapeFileError(f"{where}: {_describe(exc)}") from None
    return tuple(out)


def views_from_json(
    text: str, *, source: str = "<poses>"
) -> tuple[dict[str, tuple[CameraPose, Intrinsics]], float]:
    """Camera pose and intrinsics of the top, front and right photos, and the ground height."""
    doc = _load(text, source)
    views: dict[str, tuple[CameraPose, Intrinsics]] = {}
    for name in VIEW_NAMES:
        entry = doc.get(name)
        if not isinstance(entry, dict):
            raise ShapeFileError(f"{source}: {name}: missing (need top, front and right)")
        where = f"{source}: {name}"
        try:
            pos = tuple(_finite(v) for v in entry["pos_enu_m"])
            if len(pos) != 3:
                raise ValueError("pos_enu_m needs 3 values (east, north, up)")
            pose = CameraPose(
                (pos[0], pos[1], pos[2]), _finite(entry["heading_deg"]), _finite(entry["pitch_deg"])
            )
            views[name] = (pose, _intrinsics(entry["intrinsics"]))
        except InputError as exc:
            raise ShapeFileError(f"{where}: {exc}") from None
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise ShapeFileError(f"{where}: {_describe(exc)}") from None
    try:
        ground = _finite(doc.get("ground_z_m", 0.0))
    except (TypeError, ValueError) as exc:
        raise ShapeFileError(f"{source}: ground_z_m: {_describe(exc)}") from None
    return views, ground


def views_to_json(views: dict[str, tuple[CameraPose, Intrinsics]], ground_z_m: float = 0.0) -> str:
    """A poses document for :func:`views_from_json` (full intrinsics)."""
    doc: dict[str, Any] = {"ground_z_m": ground_z_m}
    for name, (pose, k) in views.items():
        doc[name] = {
            "pos_enu_m": list(pose.pos_enu_m),
            "heading_deg": pose.heading_deg,
            "pitch_deg": pose.pitch_deg,
            "intrinsics": {
                "width_px": k.width_px,
                "height_px": k.height_px,
                "fx_px": k.fx_px,
                "fy_px": k.fy_px,
                "cx_px": k.cx_px,
                "cy_px": k.cy_px,
            },
        }
    return json.dumps(doc, indent=1)


def _intrinsics(entry: dict[str, Any]) -> Intrinsics:
    w, h = int(entry["width_px"]), int(entry["height_px"])
    if "hfov_deg" in entry:
        return Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=_finite(entry["hfov_deg"]))
    fx, fy = _finite(entry["fx_px"]), _finite(entry["fy_px"])
    if fx <= 0 or fy <= 0 or w <= 0 or h <= 0:
        raise ValueError("intrinsics: sizes and focal lengths must be positive")
    return Intrinsics(w, h, fx, fy, _finite(entry["cx_px"]), _finite(entry["cy_px"]))


def _load(text: str, source: str) -> dict[str, Any]:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ShapeFileError(f"{source}:{exc.lineno}: invalid JSON: {exc.msg}") from None
    if not isinstance(doc, dict):
        raise ShapeFileError(f"{source}: expected a JSON object at the top level")
    return doc


def _ring(value: Any, where: str) -> FloatArray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3:
        raise ShapeFileError(f"{where}: expected at least 3 [u, v] points")
    if not np.all(np.isfinite(arr)):
        raise ShapeFileError(f"{where}: non-finite coordinate")
    return arr


def _detail(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ShapeFileError(f"{where}: expected a number of pixels")
    f = float(value)
    if not (math.isfinite(f) and f >= 0.0):
        raise ShapeFileError(f"{where}: expected a finite number of pixels >= 0, got {value!r}")
    return f


def _finite(value: Any) -> float:
    f = float(value)
    if not math.isfinite(f):
        raise ValueError(f"{value!r} is not a finite number")
    return f


def _describe(exc: Exception) -> str:
    if isinstance(exc, KeyError):
        return f"missing field {exc.args[0]!r}"
    return str(exc)
