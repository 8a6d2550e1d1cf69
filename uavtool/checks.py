"""Typed values from users, checked in one place.

A value reaches uavtool as text (a command-line option, ``--set key=value``) or as what a
parsed file holds (JSON/YAML numbers, lists, strings). :func:`coerce` turns either into a
field's type (``bool``, ``int``, ``float``, ``str``, an ``Enum``, ``tuple[T, ...]`` or a
fixed-length tuple) and checks it against a :class:`Range`; every float must be finite.
Parameter structures declare their ranges once, in a table, and call :func:`check_fields`
when built, so the command line, parameter files and code obey the same rules.

Errors are :class:`~uavtool.errors.InputError` (or the subclass the caller names) with one
line saying the name, the value and what was expected: ``mission.move_slack_s=nan: expected
a finite number ≥ 0``.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import math
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from uavtool.errors import InputError


@dataclass(frozen=True, slots=True)
class Range:
    """Closed or open bounds on a number; ``Range()`` allows any finite number."""

    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False

    def __contains__(self, value: float) -> bool:
        above = value > self.lo if self.lo_open else value >= self.lo
        below = value < self.hi if self.hi_open else value <= self.hi
        return above and below

    def __str__(self) -> str:
        lo_finite, hi_finite = math.isfinite(self.lo), math.isfinite(self.hi)
        if lo_finite and hi_finite:
            left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
            return f"in {left}{_num(self.lo)}, {_num(self.hi)}{right}"
        if lo_finite:
            return f"{'>' if self.lo_open else '≥'} {_num(self.lo)}"
        if hi_finite:
            return f"{'<' if self.hi_open else '≤'} {_num(self.hi)}"
        return ""


ANY = Range()
POSITIVE = Range(0.0, lo_open=True)
NON_NEGATIVE = Range(0.0)
FRACTION = Range(0.0, 1.0)
"""[0, 1]"""
DN = Range(0, 255)
SEED_RANGE = Range(0, 2**63 - 1)
"""Seeds: what numpy's and Python's generators take alike, and what a table's 64-bit integer
column holds."""
"""An 8-bit pixel value (digital number)."""


def coerce(
    value: object,
    hint: object,
    *,
    name: str,
    bounds: Range = ANY,
    error: type[InputError] = InputError,
) -> Any:
    """``value`` (text, or a value a parsed file holds) as type ``hint`` within ``bounds``.

    Numbers inside tuples are each checked against ``bounds``. Raises ``error`` naming
    ``name``, the value and what was expected.
    """
    try:
        parsed = _from_text(value, hint) if isinstance(value, str) and hint is not str else value
        return _conform(parsed, hint, bounds)
    except _MismatchError:
        raise error(f"{name}={_show(value)}: expected {describe(hint, bounds)}") from None


def check_fields(
    obj: object,
    ranges: Mapping[str, Range],
    *,
    group: str,
    error: type[InputError] = InputError,
) -> None:
    """Check every field of the dataclass ``obj`` against its type and ``ranges`` (floats
    not listed need only be finite); raises ``error`` for the first one that fails."""
    hints = _hints(type(obj))
    for f in dataclasses.fields(obj):  # type: ignore[arg-type]
        coerce(
            getattr(obj, f.name),
            hints[f.name],
            name=f"{group}.{f.name}",
            bounds=ranges.get(f.name, ANY),
            error=error,
        )


def field_hint(cls: type, name: str) -> Any:
    """The resolved type of field ``name`` of the dataclass ``cls``."""
    return _hints(cls)[name]


def describe(hint: object, bounds: Range = ANY) -> str:
    """What a value of type ``hint`` within ``bounds`` looks like, for error messages:
    ``a finite number ≥ 0``, ``a list of lists of 3 integers in [0, 255], e.g. [[0, 0, 0]]``."""
    if hint is bool:
        return "true or false"
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return "one of " + ", ".join(str(m.value) for m in hint)
    text = _noun(hint, bounds, plural=False)
    if typing.get_origin(hint) is tuple:
        text += f", e.g. {_example(hint)}"
    return text


def _noun(hint: object, bounds: Range, *, plural: bool) -> str:
    rule = f" {bounds}" if str(bounds) else ""
    if hint is int:
        return ("integers" if plural else "an integer") + rule
    if hint is float:
        return ("finite numbers" if plural else "a finite number") + rule
    if hint is str:
        return "strings" if plural else "a string"
    args = typing.get_args(hint)
    lists = "lists" if plural else "a list"
    if typing.get_origin(hint) is tuple and len(args) == 2 and args[1] is Ellipsis:
        return f"{lists} of {_noun(args[0], bounds, plural=True)}"
    if typing.get_origin(hint) is tuple and len(set(args)) == 1:
        return f"{lists} of {len(args)} {_noun(args[0], bounds, plural=True)}"
    return f"{lists} of {', '.join(_name(a) for a in args)}"


class _MismatchError(Exception):
    """The value does not fit the hint (turned into the caller's error by :func:`coerce`)."""


def _from_text(text: str, hint: object) -> object:
    """Command-line text → the JSON-like value it stands for."""
    stripped = text.strip()
    if hint is bool:
        words = {"true": True, "yes": True, "1": True, "false": False, "no": False, "0": False}
        if stripped.lower() not in words:
            raise _MismatchError
        return words[stripped.lower()]
    if hint is int:
        try:
            return int(stripped)
        except ValueError:
            raise _MismatchError from None
    if hint is float:
        try:
            return float(stripped)
        except ValueError:
            raise _MismatchError from None
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return stripped
    try:
        return json.loads(stripped)
    except (ValueError, RecursionError):
        raise _MismatchError from None


def _conform(value: object, hint: object, bounds: Range) -> object:
    if hint is bool:
        if not isinstance(value, bool):
            raise _MismatchError
        return value
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int) or value not in bounds:
            raise _MismatchError
        return value
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _MismatchError
        try:
            number = float(value)
        except OverflowError:
            raise _MismatchError from None
        if not math.isfinite(number) or number not in bounds:
            raise _MismatchError
        return number
    if hint is str:
        if not isinstance(value, str):
            raise _MismatchError
        return value
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        for member in hint:
            if value in (member.value, member.name) or value is member:
                return member
        raise _MismatchError
    if typing.get_origin(hint) is tuple:
        return _conform_tuple(value, typing.get_args(hint), bounds)
    raise TypeError(f"uavtool.checks: unsupported type {hint!r}")  # a programming error


def _conform_tuple(value: object, args: tuple[Any, ...], bounds: Range) -> tuple[object, ...]:
    if not isinstance(value, list | tuple):
        raise _MismatchError
    if len(args) == 2 and args[1] is Ellipsis:
        return tuple(_conform(v, args[0], bounds) for v in value)
    if len(value) != len(args):
        raise _MismatchError
    return tuple(_conform(v, a, bounds) for v, a in zip(value, args, strict=True))


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def _example(hint: object) -> str:
    args = typing.get_args(hint)
    if typing.get_origin(hint) is not tuple:
        return "1" if hint in (int, float) else '"text"'
    if len(args) == 2 and args[1] is Ellipsis:
        return f"[{_example(args[0])}]"
    return "[" + ", ".join(_example(a) for a in args) + "]"


def _num(value: float) -> str:
    return str(int(value)) if float(value).is_integer() and abs(value) < 1e15 else str(value)


def shown(value: object) -> str:
    """``repr(value)`` cut to 60 characters: a hostile value stays a short line."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _show(value: object) -> str:
    text = value if isinstance(value, str) else repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _name(hint: object) -> str:
    if isinstance(hint, types.UnionType):
        return str(hint)
    return getattr(hint, "__name__", str(hint))


MAX_HOME_M = 10_000.0
"""How far from the scene's home a fleet's home given by hand (``fly --home E,N``) may lie."""
