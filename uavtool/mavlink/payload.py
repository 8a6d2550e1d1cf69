"""A MAVLink message's fields from its payload bytes, as pymavlink's ``MAVLink.decode`` takes
them apart, without the rest of its work.

pymavlink's ``decode`` is most of what a lockstep flight's link costs per message: its
generic loops over each message's ``orders`` and ``lengths`` run again for every frame. Here
they run once per message type (`layout`); `values` then unpacks a payload to the arguments
pymavlink would give the message's constructor, in the same order and of the same types.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from operator import itemgetter
from typing import Any


@dataclass(frozen=True, slots=True)
class Layout:
    """Where each field of one message type is in its unpacked payload."""

    crc_extra: bytes
    """The type's CRC extra byte, which the frame's CRC covers after the payload."""
    size: int
    """The payload's full length; MAVLink 2 leaves out its trailing zeros on the wire."""
    unpack: Callable[[bytes], tuple[Any, ...]]
    fields: tuple[tuple[int, int | None], ...]
    """Each field in declaration order: ``(tip, None)`` for the item ``t[tip]`` of the
    unpacked tuple ``t`` (a char array is one item), ``(tip, end)`` for ``list(t[tip:end])``."""
    has_text: bool
    """Whether a field is a char array (its bytes end at their first NUL)."""
    pick: Callable[[tuple[Any, ...]], tuple[Any, ...]] | None
    """The values straight from the unpacked tuple, when every field is one number and there
    are two or more (most messages)."""


@cache
def layout(cls: Any) -> Layout:
    """The `Layout` of a pymavlink message class, as its dialect's ``decode`` works it out
    from the class's ``orders``, ``lengths`` and ``unpacker`` for every frame. Whether the
    first item of a field with a length is the whole field (a char array's bytes) or its
    first number depends on the type alone, so the unpacking of zeros says it."""
    lengths, unpacker = cls.lengths, cls.unpacker
    zeros = unpacker.unpack(bytes(unpacker.size))
    fields: list[tuple[int, int | None]] = []
    text = False
    for order in cls.orders:
        width = lengths[order]
        tip = sum(lengths[:order])
        if isinstance(zeros[tip], bytes):
            text = True
            fields.append((tip, None))
        else:
            fields.append((tip, None if width == 1 else tip + width))
    numbers = not text and len(fields) > 1 and all(end is None for _, end in fields)
    return Layout(
        bytes((cls.crc_extra,)),
        unpacker.size,
        unpacker.unpack,
        tuple(fields),
        text,
        itemgetter(*(tip for tip, _ in fields)) if numbers else None,
    )


def values(lay: Layout, payload: bytes) -> tuple[Any, ...]:
    """The fields of ``payload`` (as sent: maybe without its trailing zeros, maybe longer
    than this dialect's type) in declaration order: what pymavlink's ``decode`` passes to the
    message's constructor. Raises ``struct.error`` only as pymavlink's unpacking would."""
    if len(payload) < lay.size:
        payload += bytes(lay.size - len(payload))
    t = lay.unpack(payload[: lay.size])
    if lay.pick is not None:
        picked: tuple[Any, ...] = lay.pick(t)
        return picked
    out = tuple(t[tip] if end is None else list(t[tip:end]) for tip, end in lay.fields)
    if lay.has_text:
        out = tuple(v.rstrip(b"\x00") if isinstance(v, bytes) else v for v in out)
    return out


def frame_crc(module: Any) -> Callable[[bytes], int]:
    """The CRC of a frame's bytes as a pymavlink dialect ``module`` computes it: fastcrc's
    when pymavlink found it, else its own (the same numbers)."""
    fast = getattr(module, "mcrf4xx", None)
    if fast is not None:
        return lambda data: int(fast(data, 0xFFFF))
    return lambda data: int(module.x25crc(data).crc)
