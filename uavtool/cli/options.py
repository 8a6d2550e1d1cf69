"""Click types for numeric options, checked by :mod:`uavtool.checks`.

A bad value raises :class:`~uavtool.errors.InputError` (not click's usage error), so every
bad number reads the same: ``uavtool: error: --timeout=nan: expected a finite number > 0``
on one line, exit code 2.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import click

from uavtool.checks import ANY, SEED_RANGE, Range, coerce
from uavtool.errors import InputError


class Number(click.ParamType[Any]):
    """A finite ``float`` (or ``int`` with ``integer=True``) within ``bounds``."""

    name = "number"

    def __init__(self, bounds: Range = ANY, *, integer: bool = False) -> None:
        self.bounds = bounds
        self.hint: type = int if integer else float
        self.name = "integer" if integer else "number"

    def convert(self, value: Any, param: click.Parameter | None, _ctx: click.Context | None) -> Any:
        return coerce(value, self.hint, name=_option(param), bounds=self.bounds)


class Numbers(click.ParamType[Any]):
    """``A<sep>B…``: one finite float per named item, each within its range."""

    name = "numbers"

    def __init__(self, sep: str, items: tuple[tuple[str, Range], ...], *, example: str) -> None:
        self.sep = sep
        self.items = items
        self.example = example

    def convert(
        self, value: Any, param: click.Parameter | None, _ctx: click.Context | None
    ) -> tuple[float, ...]:
        if isinstance(value, tuple):
            return value
        option = _option(param)
        parts = str(value).split(self.sep)
        if len(parts) != len(self.items):
            names = self.sep.join(name for name, _ in self.items)
            raise InputError(f"{option}={value}: expected {names}, e.g. {self.example}")
        return tuple(
            coerce(part, float, name=f"{option} {name}", bounds=bounds)
            for part, (name, bounds) in zip(parts, self.items, strict=True)
        )


SEED = Number(SEED_RANGE, integer=True)

PORT = Number(Range(1, 65_535), integer=True)
"""A TCP port for one of our servers to listen on."""


def check_web_ports(ports: Mapping[str, int | None], *, web: bool, needs: str) -> None:
    """The web viewer's port options (option name → port, None when not given) go only with
    ``web``, the option ``needs`` that serves it."""
    given = [name for name, port in ports.items() if port is not None]
    if given and not web:
        raise InputError(f"{given[0]} goes with {needs}")


def _option(param: click.Parameter | None) -> str:
    if param is None:
        return "value"
    opts = getattr(param, "opts", None)
    return max(opts, key=len) if opts else str(param.name)
