"""Errors of the sweep: a spec that cannot be flown names the key path that is wrong."""

from __future__ import annotations

from uavtool.errors import FailureError, InputError


class SpecError(InputError):
    """A sweep spec (or a ``--set`` of it) is invalid: ``spec.toml: grid.seed[2]: …``."""

    def __init__(self, source: str, key_path: str, problem: str) -> None:
        where = f"{source}: {key_path}" if key_path else source
        super().__init__(f"{where}: {problem}")
        self.key_path = key_path


class OutputExistsError(InputError):
    """The output folder already holds a sweep and ``--resume`` was not given."""


class FlightTimeoutError(FailureError):
    """A flight went on past the sweep's ``timeout_s`` of vehicle time and was stopped."""

    def __init__(self, timeout_s: float) -> None:
        super().__init__(f"stopped after {timeout_s:g} s of vehicle time (sweep.timeout_s)")
        self.timeout_s = timeout_s
