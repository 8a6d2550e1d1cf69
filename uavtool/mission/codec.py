"""Observations and outputs as JSON-ready dicts, and observations back from them.

Floats go through Python's shortest round-trip repr, so a decoded observation is equal bit
for bit to the one recorded, and two outputs are equal exactly when their dicts are. A
photo's pixels travel separately (``/camera/image``); its dict holds the frame index.
"""

from __future__ import annotations

import dataclasses
import hashlib
from enum import Enum
from typing import Any

import numpy as np

from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission.errors import MissionInputError
from uavtool.mission.observations import (
    CommandResult,
    LinkLost,
    LinkRestored,
    Observation,
    Photo,
    Telemetry,
    U8Array,
)
from uavtool.mission.outputs import Output, Picture

_PLAIN = frozenset({int, float, str, bool, type(None)})
_FIELDS: dict[type, tuple[str, ...]] = {}
"""Each dataclass's field names, as encoded (a Photo's image left out): looked up once."""


def encode(value: Any) -> Any:
    """A dataclass tree as JSON-ready data: ``{"type": ClassName, field: …}``; arrays and
    tuples become lists, enums their value, bytes ``{"sha256", "size"}``; a field that is
    None and a Photo's image are left out."""
    kind = type(value)
    if kind in _PLAIN:
        return value
    if kind is tuple or kind is list:
        return [encode(v) for v in value]
    names = _FIELDS.get(kind)
    if names is None and dataclasses.is_dataclass(value) and not isinstance(value, type):
        names = tuple(f.name for f in dataclasses.fields(value) if f.name != "image_rgb")
        _FIELDS[kind] = names
    if names is not None:
        out: dict[str, Any] = {"type": kind.__name__}
        for name in names:
            if name == "roll_deg" and kind is CameraPose and value.roll_deg == 0.0:
                continue  # a level camera is written as before rolls were recorded
            field = getattr(value, name)
            if field is not None:  # no value: no field (JSON Schema validators accept that)
                out[name] = encode(field)
        return out
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, (tuple, list)):
        return [encode(v) for v in value]
    if isinstance(value, bytes):
        return {"sha256": hashlib.sha256(value).hexdigest(), "size": len(value)}
    if isinstance(value, np.generic):
        return value.item()
    return value


def encode_output(output: Output) -> dict[str, Any]:
    return encode(output)  # type: ignore[no-any-return]


def encode_observation(obs: Observation) -> dict[str, Any]:
    return encode(obs)  # type: ignore[no-any-return]


def without_nulls(value: Any) -> Any:
    """``value`` with every null field of its objects left out, as :func:`encode` writes them
    now (recordings before it wrote ``null``): the same output compares equal from either."""
    if isinstance(value, dict):
        return {k: without_nulls(v) for k, v in value.items() if v is not None}
    if isinstance(value, list):
        return [without_nulls(v) for v in value]
    return value


def decode_observation(data: dict[str, Any], image_rgb: U8Array | None = None) -> Observation:
    """The observation a dict from :func:`encode_observation` stands for. A photo needs its
    image; raises MissionInputError on a malformed dict (saying which field)."""
    kind = data.get("type")
    try:
        if kind == "Telemetry":
            return Telemetry(
                int(data["time_boot_ms"]),
                _vec3(data["pos_enu_m"]),
                _vec3(data["vel_enu_m_s"]),
                float(data["heading_deg"]),
                str(data["mode"]),
                bool(data["armed"]),
                bool(data["landed"]),
                float(data["gimbal_pitch_deg"]),
                float(data["gimbal_yaw_deg"]),
                int(data["battery_pct"]),
            )
        if kind == "CommandResult":
            return CommandResult(  # recordings before "final" have none: not final
                int(data["action_id"]),
                bool(data["accepted"]),
                str(data["detail"]),
                bool(data.get("final", False)),
            )
        if kind == "LinkLost":
            return LinkLost(float(data["silent_s"]))
        if kind == "LinkRestored":
            return LinkRestored(float(data["silent_s"]))
        if kind == "Photo":
            if image_rgb is None:
                raise MissionInputError(f"photo {data.get('frame_index')}: its image is missing")
            pose, intrinsics = decode_camera(data)
            return Photo(
                int(data["action_id"]),
                int(data["frame_index"]),
                str(data["tag"]),
                int(data["time_boot_ms"]),
                pose,
                intrinsics,
                image_rgb,
            )
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise MissionInputError(f"observation {kind}: bad or missing field {exc}") from None
    raise MissionInputError(f"unknown observation type {kind!r}")


def decode_camera(data: dict[str, Any]) -> tuple[CameraPose, Intrinsics]:
    """The camera pose and intrinsics of an encoded photo or frame record (its ``pose`` and
    ``intrinsics`` fields). Raises KeyError, TypeError or ValueError on a malformed one."""
    pose, k = data["pose"], data["intrinsics"]
    return (
        CameraPose(
            _vec3(pose["pos_enu_m"]),
            float(pose["heading_deg"]),
            float(pose["pitch_deg"]),
            float(pose.get("roll_deg", 0.0)),
        ),
        Intrinsics(
            int(k["width_px"]),
            int(k["height_px"]),
            float(k["fx_px"]),
            float(k["fy_px"]),
            float(k["cx_px"]),
            float(k["cy_px"]),
        ),
    )


def _vec3(value: Any) -> tuple[float, float, float]:
    x, y, z = value
    return (float(x), float(y), float(z))


def output_bytes(out: Output) -> bytes | None:
    """The bytes an output carries beside its JSON form (which holds only their digest): a
    picture's PNG."""
    return out.png if isinstance(out, Picture) else None
