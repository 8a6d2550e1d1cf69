"""JSON schemas of the observation and output dicts (`uavtool.mission.codec`), built from the
dataclasses themselves so they cannot drift from what is recorded.

One object schema per union: ``type`` names the dataclass, every other property is the union
of the variants' fields (a field name means the same thing wherever it appears). The rule of
`uavtool.recording.schemas` holds: one JSON type per field; a field with no value is left out
(no field is required but ``type``). Nested
lists (polygons, mesh vertices) are left out of ``properties``: Foxglove's and Lichtblick's
parsers accept no array of arrays and would drop the channel; the values are still in each
message and listed in the schema's description.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from enum import Enum
from typing import Any

import numpy as np

from uavtool.mission.observations import Observation
from uavtool.mission.outputs import Output

_SCALARS: dict[type, str] = {bool: "boolean", int: "integer", float: "number", str: "string"}
_BYTES = {
    "type": "object",
    "description": "bytes, by digest (the bytes travel on their own topic)",
    "properties": {"sha256": {"type": "string"}, "size": {"type": "integer"}},
}


class _NestedError(Exception):
    """A type with no schema Foxglove accepts (an array of arrays, an object of any keys)."""


def _unalias(tp: Any) -> Any:
    """What a type alias stands for, its parameters substituted.

    ``type X[T] = ...`` (and numpy's ``NDArray`` on Python 3.12+, a ``typing.TypeAliasType``)
    is opaque to ``typing.get_origin``: ``NDArray[np.float64]`` has the alias as its origin,
    not ``np.ndarray``. Its ``__value__`` is the aliased type, generic in ``__type_params__``.
    """
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if _is_alias(tp):
        return _unalias(tp.__value__)
    if _is_alias(origin):
        value, params = origin.__value__, origin.__type_params__
        if params and args:
            value = value[args if len(args) > 1 else args[0]]
        return _unalias(value)
    return tp


def _is_alias(tp: Any) -> bool:
    # typing.TypeAliasType (3.12+) or typing_extensions' backport of it, by what they carry
    return hasattr(tp, "__value__") and hasattr(tp, "__type_params__") and not isinstance(tp, type)


def _variants(tp: Any) -> tuple[Any, ...]:
    tp = _unalias(tp)
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        return tuple(_unalias(a) for a in typing.get_args(tp))
    return (tp,)


def _is_array(tp: Any) -> bool:
    tp = _unalias(tp)
    return typing.get_origin(tp) is tuple or tp is np.ndarray or typing.get_origin(tp) is np.ndarray


def _item_type(tp: Any) -> Any:
    tp = _unalias(tp)
    args = [a for a in typing.get_args(tp) if a is not Ellipsis]
    if tp is np.ndarray or typing.get_origin(tp) is np.ndarray:
        raise _NestedError  # arrays of the mission are 2-D (polygons, point lists)
    if not args or any(a != args[0] for a in args):
        raise _NestedError
    return args[0]


def _schema(tp: Any) -> dict[str, Any]:
    variants = [v for v in _variants(tp) if v is not type(None)]
    nullable = len(variants) < len(_variants(tp))
    if len(variants) > 1 and all(dataclasses.is_dataclass(v) for v in variants):
        schema = _object(variants)
    elif len(variants) != 1:
        raise TypeError(f"no JSON schema for {tp!r}: a field must have one JSON type")
    else:
        schema = _one(variants[0])
    if nullable:
        schema["description"] = "absent: not set"
    return schema


def _one(tp: Any) -> dict[str, Any]:
    tp = _unalias(tp)
    if tp in _SCALARS:
        return {"type": _SCALARS[tp]}
    if tp is bytes:
        return dict(_BYTES)
    if typing.get_origin(tp) is dict:
        raise _NestedError  # any keys: no schema Foxglove's parser takes (it needs properties)
    if isinstance(tp, type) and issubclass(tp, Enum):
        values = [m.value for m in tp]
        kind = "integer" if all(isinstance(v, int) for v in values) else "string"
        return {"type": kind, "description": "one of " + ", ".join(map(str, values))}
    if dataclasses.is_dataclass(tp):
        return _object([tp])
    if _is_array(tp):
        item = _item_type(tp)
        if _is_array(item):
            raise _NestedError
        return {"type": "array", "items": _schema(item)}
    raise TypeError(f"no JSON schema for {tp!r}")


def _object(classes: list[Any]) -> dict[str, Any]:
    """One object schema for the dataclasses ``classes``, discriminated by ``type``."""
    properties: dict[str, Any] = {"type": {"type": "string"}}
    nested: list[str] = []
    for cls in classes:
        hints = typing.get_type_hints(cls)
        for f in dataclasses.fields(cls):
            if f.name == "image_rgb":  # a photo's pixels are on /camera/image
                continue
            try:
                schema = _schema(hints[f.name])
            except _NestedError:
                nested.append(f"{cls.__name__}.{f.name}")
                continue
            known = properties.setdefault(f.name, schema)
            if known.get("type") != schema.get("type"):
                raise TypeError(f"field {f.name!r} has two JSON types in {classes}")
    names = ", ".join(c.__name__ for c in classes)
    description = f"type: {names}"
    if nested:
        description += "; nested lists and free-form objects not typed here: " + ", ".join(nested)
    return {"type": "object", "description": description, "properties": properties}


def _union_schema(union: Any, title: str, head: dict[str, Any], intro: str) -> dict[str, Any]:
    body = _object(list(_variants(union)))
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": title,
        "description": f"{intro} {body['description']}. A field with no value is absent.",
        "type": "object",
        "properties": {**head, **body["properties"]},
        "required": [*head, "type"],
    }


def observation_schema() -> dict[str, Any]:
    """The JSON schema of ``/mission/observations`` (``uavtool.Observation``)."""
    return _union_schema(
        Observation,
        "uavtool.Observation",
        {"step": {"type": "integer", "description": "order in which the mission consumed it"}},
        "What the mission consumed, in order (a Photo's pixels are on /camera/image).",
    )


def output_schema() -> dict[str, Any]:
    """The JSON schema of ``/mission/outputs`` (``uavtool.Output``)."""
    return _union_schema(
        Output,
        "uavtool.Output",
        {
            "n": {"type": "integer", "description": "output number, from 1"},
            "step": {"type": "integer", "description": "the observation that produced it"},
        },
        "What the mission produced, in order.",
    )
