"""Checks for the numbers that commands and mission items carry.

MAVLink sends most arguments as float32 (COMMAND_LONG's params) even where they mean an
integer: an id, a flag set, a count. These turn such a float into the integer it means, or
None when it cannot be one (NaN, ±∞, out of the field's range), so that handlers refuse it
with a reason instead of failing on it.
"""

from __future__ import annotations

import math

UINT8_MAX = 2**8 - 1
UINT16_MAX = 2**16 - 1
UINT32_MAX = 2**32 - 1
MSG_ID_MAX = 2**24 - 1


def whole(value: float, low: int, high: int) -> int | None:
    """``value`` truncated to an integer (as ArduPilot's casts do) if it is finite and within
    ``low``…``high``; else None."""
    if not (math.isfinite(value) and low <= value <= high):
        return None
    return int(value)


def lat_lon_ok(lat_deg: float, lon_deg: float) -> bool:
    """A WGS-84 latitude and longitude that exist (finite, |lat| ≤ 90, |lon| ≤ 180)."""
    return (
        math.isfinite(lat_deg)
        and math.isfinite(lon_deg)
        and abs(lat_deg) <= 90.0
        and abs(lon_deg) <= 180.0
    )
