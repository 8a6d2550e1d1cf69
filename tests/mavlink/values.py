"""Random field values for every MAVLink field type, for tests that fill every message type
of the dialect: text with quotes, backslashes, '%', control and non-ASCII bytes; floats
either plain float32 values or awkward ones too (NaN, infinities, -0.0, extremes); integers
at their limits, zero and anywhere between; each message type filled so and sent, and a
frame's damaged variants."""

from __future__ import annotations

import random
import struct
from collections.abc import Iterator
from typing import Any

AWKWARD_FLOATS = (0.0, -0.0, 1.5, -2.25e-5, 3.4e38, -3.4e38, 1e16)
AWKWARD_FLOATS += (float("nan"), float("inf"), -1e-45)
TEXT = b'a"b\\c%d%%s\x01\x1fe\x7f\xc3\xa9\xff\x00'
_BITS = {"int8_t": 8, "uint8_t": 8, "int16_t": 16, "uint16_t": 16}
_BITS |= {"int32_t": 32, "uint32_t": 32, "int64_t": 64, "uint64_t": 64}


def value(rng: random.Random, ftype: str, length: int, *, awkward: bool) -> object:
    """A value for a field of MAVLink type ``ftype`` (an array of ``length`` when not 0);
    ``awkward``: floats drawn from :data:`AWKWARD_FLOATS` as well as plain ones."""
    if ftype == "char":
        return bytes(rng.choice(TEXT) for _ in range(rng.randint(0, length)))
    if ftype in ("float", "double"):

        def pick() -> float:
            plain = struct.unpack("<f", struct.pack("<f", rng.uniform(-1e4, 1e4)))[0]
            return rng.choice([*AWKWARD_FLOATS, plain]) if awkward else plain

        return [pick() for _ in range(length)] if length else pick()
    bits, signed = _BITS[ftype], ftype[0] == "i"
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)

    def pick_int() -> int:
        return rng.choice([lo, hi, 0, rng.randint(lo, hi)])

    return [pick_int() for _ in range(length)] if length else pick_int()


def every_message(
    module: Any, rng: random.Random, rounds: int, *, awkward: bool
) -> Iterator[tuple[Any, bytes]]:
    """``rounds`` times, each message class of the pymavlink dialect ``module`` filled with
    :func:`value`\\ s, and its frame as sent by system 7, component 42."""
    sender = module.MAVLink(None, srcSystem=7, srcComponent=42)
    for _ in range(rounds):
        for cls in module.mavlink_map.values():
            lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
            args = [
                value(rng, ftype, lengths[name], awkward=awkward)
                for name, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)
            ]
            yield cls, bytes(cls(*args).pack(sender))


def variants(frame: bytes, msg: Any, signer: Any, v1: Any, rng: random.Random) -> list[bytes]:
    """``frame`` (of message ``msg``) cut short, lengthened, signed by ``signer``, in
    MAVLink 1 by ``v1`` (when its id fits), and with 60 single bytes changed at random."""
    out = [frame[:-3], frame + b"\x00", bytes(msg.pack(signer))]
    if msg.get_msgId() < 256:
        out.append(bytes(msg.pack(v1, force_mavlink1=True)))
    for _ in range(60):
        i = rng.randrange(len(frame))
        out.append(frame[:i] + bytes([rng.randrange(256)]) + frame[i + 1 :])
    return out
