"""What a sweep may vary per flight, and how a spec value becomes a flight input.

Keys: ``seed`` (SITL wind/noise seed), ``wind_speed_ms``, ``wind_from_deg``, ``noise``
(seeded camera noise), ``home_heading_deg`` (overrides the scene's), ``link_outages`` (a
list of ``[start_s, duration_s]``), ``outage_start_s`` / ``outage_duration_s`` (one outage,
for random draws), ``vehicles`` (a fleet of that many built-in vehicles: the mission must be a
fleet mission), ``set.GROUP.NAME`` (a mission parameter, as ``uavtool fly --set``) and
``param.NAME`` (a vehicle parameter, as ``uavtool fly --param``).
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Callable
from typing import Any

from uavtool.checks import SEED_RANGE, shown
from uavtool.errors import InputError

SET_PREFIX = "set."
PARAM_PREFIX = "param."

Check = Callable[[Any], Any]
"""Converts one value or raises ValueError with the problem."""


def _number(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"expected a number, got {shown(value)}")
    return float(value)


def _non_negative(value: Any) -> float:
    number = _number(value)
    if number < 0:
        raise ValueError(f"must be ≥ 0, got {shown(value)}")
    return number


def _seed(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value not in SEED_RANGE:
        raise ValueError(f"expected a whole number {SEED_RANGE}, got {shown(value)}")
    return value


def _flag(value: Any) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"expected true or false, got {shown(value)}")
    return value


MAX_SWEEP_VEHICLES = 16


def _vehicles(value: Any) -> int:
    if (
        isinstance(value, bool)
        or not isinstance(value, int)
        or not 1 <= value <= MAX_SWEEP_VEHICLES
    ):
        raise ValueError(f"expected a whole number 1..{MAX_SWEEP_VEHICLES}, got {shown(value)}")
    return value


def _outages(value: Any) -> tuple[tuple[float, float], ...]:
    if not isinstance(value, list):
        raise ValueError(f"expected a list of [start_s, duration_s] pairs, got {shown(value)}")
    out = []
    for pair in value:
        if not isinstance(pair, list) or len(pair) != 2:
            raise ValueError(f"expected [start_s, duration_s], got {shown(pair)}")
        start_s, duration_s = _non_negative(pair[0]), _number(pair[1])
        if duration_s <= 0:
            raise ValueError(f"an outage lasts > 0 s, got {shown(pair)}")
        out.append((start_s, duration_s))
    return tuple(out)


_BUILTIN: dict[str, Check] = {
    "seed": _seed,
    "wind_speed_ms": _non_negative,
    "wind_from_deg": _number,
    "noise": _flag,
    "home_heading_deg": _number,
    "link_outages": _outages,
    "outage_start_s": _non_negative,
    "outage_duration_s": _non_negative,
    "vehicles": _vehicles,
}

BUILTIN_KEYS: tuple[str, ...] = tuple(_BUILTIN)


def setting_text(value: Any) -> str:
    """A spec value as ``uavtool fly --set KEY=TEXT`` takes it (so it is checked the same way)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    return json.dumps(value)


def check(key: str, value: Any, params_type: type | None = None) -> Any:
    """``value`` for dimension ``key`` in the type a flight takes (``set.*`` keys are
    parameters of ``params_type``, the mission's; default the built-in search's); ValueError
    says what is wrong, KeyError when ``key`` is no dimension at all."""
    if key in _BUILTIN:
        return _BUILTIN[key](value)
    if key.startswith(SET_PREFIX):
        from uavtool.mission.params import Params, valid_keys, with_overrides  # noqa: PLC0415

        root = params_type or Params
        name = key[len(SET_PREFIX) :]
        if name not in (known := valid_keys(root)):
            close = difflib.get_close_matches(name, known, n=3, cutoff=0.75)
            hint = (
                f"did you mean {' or '.join(close)}?"
                if close
                else "see `uavtool missions NAME` for its parameters"
            )
            raise KeyError(f"unknown mission parameter {shown(name)}; {hint}")
        try:
            with_overrides(root(), {key[len(SET_PREFIX) :]: setting_text(value)}, source="set")
        except InputError as exc:
            raise ValueError(str(exc).removeprefix("set: ")) from None
        return value
    if key.startswith(PARAM_PREFIX):
        from uavtool.sitl.params import PARAM_SPECS  # noqa: PLC0415

        name = key[len(PARAM_PREFIX) :]
        if name not in {s.name for s in PARAM_SPECS}:
            raise KeyError(f"the built-in vehicle has no parameter {shown(name)}")
        return _number(value)
    raise KeyError(
        f"unknown flight input; use one of {', '.join(BUILTIN_KEYS)}, "
        f"{SET_PREFIX}GROUP.NAME (a mission parameter) or {PARAM_PREFIX}NAME (a vehicle parameter)"
    )
