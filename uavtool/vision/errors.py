"""Errors raised by the vision stages; all are bad input (exit code 2)."""

from __future__ import annotations

from uavtool.errors import InputError


class VisionError(InputError):
    """Root of the vision errors."""


class VisionParamError(VisionError):
    """A vision parameter is out of range."""


class ImageError(VisionError):
    """An image is unreadable or has the wrong shape or type."""


class ShapeFileError(VisionError):
    """A shapes JSON or poses JSON file is malformed."""


class ModelInputError(VisionError):
    """The three projections cannot make a model (wrong poses, missing or cut silhouettes)."""
