"""Whether a message's values fit the wire types of its fields.

pymavlink packs with ``struct`` and raises ``struct.error`` (or ``OverflowError``) from deep
inside ``pack`` when one value does not fit. :func:`misfit` names the field instead, so that
a sender can refuse the message with a reason a person can act on.
"""

from __future__ import annotations

import math
from typing import Any

INT_RANGES = {  # the range of each MAVLink integer wire type
    "int8_t": (-(2**7), 2**7 - 1),
    "uint8_t": (0, 2**8 - 1),
    "int16_t": (-(2**15), 2**15 - 1),
    "uint16_t": (0, 2**16 - 1),
    "int32_t": (-(2**31), 2**31 - 1),
    "uint32_t": (0, 2**32 - 1),
    "int64_t": (-(2**63), 2**63 - 1),
    "uint64_t": (0, 2**64 - 1),
}
FLOAT32_MAX = 3.4028234663852886e38


def misfit(msg: Any) -> str | None:
    """``'FIELD=VALUE does not fit TYPE'`` for the first field of ``msg`` (a pymavlink message)
    whose value its wire type cannot carry; None when every field fits. NaN and ±∞ fit a float
    (MAVLink uses NaN for "unknown"); a finite float beyond float32's range does not."""
    lengths = dict(zip(msg.ordered_fieldnames, msg.array_lengths, strict=True))  # wire order
    for name, ftype in zip(msg.fieldnames, msg.fieldtypes, strict=True):
        value, length = getattr(msg, name), lengths[name]
        if ftype == "char":
            size = len(value.encode() if isinstance(value, str) else value)
            if length and size > length:
                return f"{name} ({size} bytes) does not fit char[{length}]"
            continue
        values = value if length else [value]
        if length and len(values) != length:
            return f"{name} has {len(values)} items, not {length}"
        for item in values:
            problem = _misfit_scalar(ftype, item)
            if problem is not None:
                return f"{name}={item!r} does not fit {ftype}{problem}"
    return None


def _misfit_scalar(ftype: str, value: Any) -> str | None:
    if ftype in ("float", "double"):
        if not isinstance(value, (int, float)):
            return ""
        if ftype == "float" and math.isfinite(value) and abs(value) > FLOAT32_MAX:
            return " (beyond float32)"
        return None
    low, high = INT_RANGES[ftype]
    if not isinstance(value, int):
        return " (not an integer)"
    if not low <= value <= high:
        return f" ({low}..{high})"
    return None
