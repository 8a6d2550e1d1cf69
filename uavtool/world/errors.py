"""Errors of the world package."""

from __future__ import annotations

from uavtool.errors import InputError


class SceneError(InputError):
    """A scene file or scene data is invalid; the message names the file, line and key path."""
