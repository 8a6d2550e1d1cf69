"""Errors of the viewer: a recording it cannot show, a viewer it cannot start."""

from __future__ import annotations

from uavtool.errors import InputError


class ViewError(InputError):
    """A recording holds no mission to show, or the viewer cannot be served as asked."""


class PortInUseError(ViewError):
    """A port the web viewer's servers are to listen on is taken."""
