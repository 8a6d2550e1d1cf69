"""Errors of the sweep: a spec that cannot be flown names the key path that is wrong."""

from __future__ import annotations

from uavtool.errors import InputError


class SpecError(InputError):
    """A sweep spec (or a ``--override`` of it) is invalid: ``spec.toml: grid.seed[2]: …``."""

    def __init__(self, source: str, key_path: str, problem: str) -> None:
        where = f"{source}: {key_path}" if key_path else source
        super().__init__(f"{where}: {problem}")
        self.key_path = key_path


class OutputExistsError(InputError):
    """The output folder already holds a sweep and ``--resume`` was not given."""
