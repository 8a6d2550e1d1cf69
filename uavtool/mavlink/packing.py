"""A message's MAVLink 2 frame, byte for byte as pymavlink's ``pack`` makes it, at a third of
its cost.

pymavlink's ``pack`` builds a header object, a byte array it grows three times and a CRC
object for every frame; the built-in vehicle sends ~13 k frames a lockstep flight, and that
was a tenth of the flight's time. Here the fields' order and the type's constants are worked
out once per message type (`packing`), and `pack` makes an unsigned frame with two struct
packs and one CRC. A signed frame is left to pymavlink.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from operator import attrgetter, itemgetter
from typing import Any

from uavtool.mavlink.dialect import mavlink
from uavtool.mavlink.payload import frame_crc

_HEADER = struct.Struct("<BBBBBBBHB")
_crc16 = frame_crc(mavlink)


@dataclass(frozen=True, slots=True)
class Packing:
    """What packing one message type takes, worked out once."""

    args: Callable[[Any], tuple[Any, ...]]
    """A message's values in wire order, as its ``pack`` hands them to the struct: array
    fields item by item, char arrays as the bytes they were given."""
    pack: Callable[..., bytes]
    msgid_lo: int
    msgid_hi: int
    crc_extra: bytes


@cache
def packing(cls: Any) -> Packing | None:
    """The `Packing` of a pymavlink message class: the order its generated ``pack`` takes
    the fields in (``ordered_fieldnames``; a char array's raw bytes; an array of more than
    one item indexed item by item). None for a class whose ``pack`` pymavlink's generator
    did not write (`uavtool.mavlink.events`)."""
    if cls.pack.__module__ != mavlink.__name__:
        return None
    types = dict(zip(cls.fieldnames, cls.fieldtypes, strict=True))
    parts: list[tuple[str, int]] = []
    for name, length in zip(cls.ordered_fieldnames, cls.array_lengths, strict=True):
        char = types[name] == "char"
        parts.append((f"_{name}_raw" if char else name, 0 if char else length))
    args: Callable[[Any], tuple[Any, ...]]
    if all(length <= 1 for _, length in parts):
        get = attrgetter(*(name for name, _ in parts))
        args = get if len(parts) > 1 else (lambda msg: (get(msg),))
    else:
        # an array's items as the generated code takes them: t[0], t[1], ... (IndexError if short)
        items = [(attrgetter(n), itemgetter(*range(k)) if k > 1 else None) for n, k in parts]

        def args(msg: Any) -> tuple[Any, ...]:
            out: list[Any] = []
            for get_field, get_items in items:
                value = get_field(msg)
                if get_items is None:
                    out.append(value)
                else:
                    out.extend(get_items(value))
            return tuple(out)

    return Packing(args, cls.unpacker.pack, cls.id & 0xFFFF, cls.id >> 16, bytes((cls.crc_extra,)))


def _frame(p: Packing, msg: Any, seq: int, sysid: int, compid: int) -> bytes:
    payload = p.pack(*p.args(msg))
    # MAVLink 2 leaves out the payload's trailing zeros, but never its first byte
    payload = payload.rstrip(b"\x00") or payload[:1]
    body = _HEADER.pack(253, len(payload), 0, 0, seq, sysid, compid, p.msgid_lo, p.msgid_hi)
    body += payload
    return body + _crc16(body[1:] + p.crc_extra).to_bytes(2, "little")


def pack(msg: Any, mav: Any) -> bytes:
    """``bytes(msg.pack(mav))``, byte for byte, and raising what it raises (``struct.error``
    for a value its field cannot carry): made here when the frame is an unsigned MAVLink 2
    one of a generated message type, else by pymavlink. The caller steps ``mav.seq``, as
    with pymavlink."""
    p = packing(msg.__class__)
    if p is None or mav.signing.sign_outgoing or mavlink.WIRE_PROTOCOL_VERSION != "2.0":
        return bytes(msg.pack(mav))
    return _frame(p, msg, mav.seq, mav.srcSystem, mav.srcComponent)
