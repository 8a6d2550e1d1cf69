"""The exception tree: every error the library raises on purpose derives from UavtoolError.

The CLI maps `InputError` (bad usage, a bad file, garbage on a link) to exit code 2 and
`FailureError` (a mission or a check that ran and failed) to exit code 1, printing the
message on one line. Messages say what failed and where, e.g.
``scene.yaml: buildings[2].footprint: self-intersecting polygon``.
"""

from __future__ import annotations

INCOMPLETE_EXIT = 3
"""Exit code of a command that did its work on less than it was asked for: a recording that
ended early (`record`) or a truncated file read up to its cut (`export`, `view`, `replay`).
Its output is whole as far as it goes and is kept; the last line, ``incomplete: …``, says
what is missing."""


class UavtoolError(Exception):
    """Root of all uavtool errors."""

    exit_code = 1


class InputError(UavtoolError):
    """The user gave us something we cannot use: a bad file, option or address."""

    exit_code = 2


class FailureError(UavtoolError):
    """The work ran and failed: a mission aborted, a replay check found a difference."""

    exit_code = 1


class LinkError(InputError):
    """A MAVLink endpoint could not be opened, or a vehicle stopped answering."""


class ParamError(InputError):
    """A parameter file or a parameter value is invalid."""
