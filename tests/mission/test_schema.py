"""The JSON schemas of /mission/observations and /mission/outputs, built from the dataclasses,
whatever spelling of a type the field uses: a plain class, a union, or a type alias
(``type X[T] = ...``; numpy's ``NDArray`` is one on Python 3.12+ with numpy 2.5)."""

from __future__ import annotations

import dataclasses
import typing
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt
import pytest

from uavtool.mission.schema import _object, observation_schema, output_schema


def _alias_type() -> Any:
    """``typing.TypeAliasType`` (3.12+), or its backport where the interpreter has none."""
    found = getattr(typing, "TypeAliasType", None)
    if found is None:
        found = pytest.importorskip("typing_extensions").TypeAliasType
    return found


_T = TypeVar("_T", bound=np.generic)
_ALIAS = _alias_type()
Array = _ALIAS("Array", np.ndarray[tuple[Any, ...], np.dtype[_T]], type_params=(_T,))
Floats = _ALIAS("Floats", tuple[float, ...])
MaybeFloats = _ALIAS("MaybeFloats", Floats | None)


@dataclasses.dataclass(frozen=True)
class _Probe:
    points: Array[np.float64]
    numpy_points: npt.NDArray[np.float64]
    speeds: Floats
    gusts: MaybeFloats
    name: str


def test_type_aliases_are_read_through() -> None:
    schema = _object([_Probe])
    props = schema["properties"]
    assert props["speeds"] == {"type": "array", "items": {"type": "number"}}
    assert props["gusts"]["type"] == "array"
    assert props["gusts"]["items"] == {"type": "number"}
    assert props["gusts"]["description"] == "absent: not set"
    assert props["name"] == {"type": "string"}
    # 2-D arrays are no type Foxglove accepts: named in the description, not typed
    assert "points" not in props
    assert "numpy_points" not in props
    assert "_Probe.points" in schema["description"]
    assert "_Probe.numpy_points" in schema["description"]


def test_a_field_type_with_no_json_form_is_refused() -> None:
    @dataclasses.dataclass(frozen=True)
    class Bad:
        when: complex

    with pytest.raises(TypeError, match="no JSON schema for <class 'complex'>"):
        _object([Bad])


@pytest.mark.parametrize("build", [observation_schema, output_schema])
def test_every_field_has_one_json_type(build: Any) -> None:
    schema = build()
    assert schema["required"][-1] == "type"
    for name, prop in schema["properties"].items():
        assert isinstance(prop.get("type"), str), name
