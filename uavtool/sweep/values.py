"""The value forms of a spec: lists and ranges for the grid, distributions for random draws.

Grid: a scalar (one value), a list, ``{first = A, count = N}`` (whole numbers A … A+N−1) or
``{from = A, to = B, step = S}`` (A, A+S, … up to B inclusive).
Random: a scalar (always that value), ``{uniform = [LO, HI]}``, ``{integers = [LO, HI]}``
(inclusive) or ``{choice = [V, …]}``.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from enum import Enum
from typing import Any

MAX_RANGE = 1_000_000


def value_list(raw: Any, *, list_valued: bool = False) -> list[Any]:
    """The values of one grid entry; ValueError says what is wrong. ``list_valued``: each value
    is itself a list (link outages), so a list is always a list of values."""
    if isinstance(raw, dict):
        if set(raw) == {"first", "count"}:
            first, count = raw["first"], raw["count"]
            if not all(isinstance(v, int) and not isinstance(v, bool) for v in (first, count)):
                raise ValueError("first and count must be whole numbers")
            if not 1 <= count <= MAX_RANGE:
                raise ValueError(f"count must be in 1..{MAX_RANGE}, got {count}")
            return list(range(first, first + count))
        if set(raw) in ({"from", "to", "step"}, {"from", "to"}):
            return _stepped(raw["from"], raw["to"], raw.get("step", 1))
        raise ValueError(
            f"a table here is {{first, count}} or {{from, to, step}}, got keys {sorted(raw)}"
        )
    if isinstance(raw, list) and (not list_valued or all(isinstance(v, list) for v in raw)):
        if not raw:
            raise ValueError("an empty list gives no flights")
        return list(raw)
    return [raw]


def _stepped(lo: Any, hi: Any, step: Any) -> list[Any]:
    values = (lo, hi, step)
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in values):
        raise ValueError("from, to and step must be numbers")
    if not step > 0 or hi < lo:
        raise ValueError(f"need step > 0 and to ≥ from, got {lo}..{hi} step {step}")
    count = math.floor((hi - lo) / step + 1e-9) + 1
    if count > MAX_RANGE:
        raise ValueError(f"{count} values: at most {MAX_RANGE}")
    whole = all(isinstance(v, int) for v in values)
    return [lo + i * step if whole else round(lo + i * step, 9) for i in range(count)]


class Law(Enum):
    """How a random dimension is drawn."""

    CONSTANT = "constant"
    UNIFORM = "uniform"
    INTEGERS = "integers"
    CHOICE = "choice"


@dataclass(frozen=True, slots=True)
class Distribution:
    law: Law
    args: tuple[Any, ...]

    def draw(self, rng: random.Random) -> Any:
        """One value; only ``rng.random()`` is used, so draws are the same in every Python."""
        if self.law is Law.CONSTANT:
            return self.args[0]
        if self.law is Law.UNIFORM:
            lo, hi = self.args
            return round(lo + (hi - lo) * rng.random(), 9)
        if self.law is Law.INTEGERS:
            lo, hi = self.args
            return lo + min(int(rng.random() * (hi - lo + 1)), hi - lo)
        return self.args[min(int(rng.random() * len(self.args)), len(self.args) - 1)]

    def support(self) -> list[Any]:
        """Values to check against the dimension: the bounds, or every choice."""
        return list(self.args)


def distribution(raw: Any) -> Distribution:
    """One ``[random]`` entry; ValueError says what is wrong."""
    if not isinstance(raw, dict):
        return Distribution(Law.CONSTANT, (raw,))
    if len(raw) != 1 or next(iter(raw)) not in {"uniform", "integers", "choice"}:
        raise ValueError(
            "expected {uniform = [LO, HI]}, {integers = [LO, HI]} or {choice = [...]}, "
            f"got keys {sorted(raw)}"
        )
    ((name, args),) = raw.items()
    if not isinstance(args, list) or not args:
        raise ValueError(f"{name} takes a non-empty list")
    law = Law(name)
    if law is Law.CHOICE:
        return Distribution(law, tuple(args))
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in args)
    if len(args) != 2 or not numbers or args[1] < args[0]:
        raise ValueError(f"{name} takes [LO, HI] with LO ≤ HI, got {args!r}")
    if law is Law.INTEGERS and not all(isinstance(v, int) for v in args):
        raise ValueError(f"integers takes whole numbers, got {args!r}")
    return Distribution(law, (args[0], args[1]))
