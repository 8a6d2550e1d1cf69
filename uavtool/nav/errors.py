"""Errors raised by navigation.

A geometric impossibility met while flying (a pixel above the horizon, a degenerate
footprint) is a :class:`NavError` (exit code 1); a parameter out of range is a
:class:`NavParamError` (bad input, exit code 2).
"""

from __future__ import annotations

from uavtool.errors import FailureError, ParamError


class NavError(FailureError):
    """A navigation computation has no answer for its inputs."""


class NavParamError(ParamError):
    """A navigation parameter is out of range."""
