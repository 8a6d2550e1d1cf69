"""Mission errors."""

from __future__ import annotations

from uavtool.errors import FailureError, InputError


class MissionInputError(InputError):
    """The mission's inputs (target image, parameters) are unusable."""


class MissionStateError(FailureError):
    """The mission was driven wrongly (stepped before start or after its end)."""
