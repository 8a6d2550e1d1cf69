"""The JSON view of a MAVLink message as the writer makes it (`MavlinkDecoder.json`: one
generated template per message type) is byte for byte what ``dumps(view(msg))`` writes (the
dict the null rule describes, through `json`): for every frame of every golden, and for
every message type of the dialect filled with awkward values (NaN, infinities, -0.0, floats
whose sum overflows, quotes, backslashes, '%' and control characters in text)."""

from __future__ import annotations

import random
import struct
from pathlib import Path

import pytest

from uavtool.recording import RecordingReader, rawframe
from uavtool.recording.schemas import MAVLINK_RAW, MavlinkDecoder, dialect_module, dumps

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))
_FLOATS = [0.0, -0.0, 1.5, -2.25e-5, 3.4e38, -3.4e38, 1e16, float("nan"), float("inf"), -1e-45]
_TEXT = b'a"b\\c%d%%s\x01\x1fe\x7f\xc3\xa9\xff'
_INTS = {"int8_t": 8, "uint8_t": 8, "int16_t": 16, "uint16_t": 16}
_INTS |= {"int32_t": 32, "uint32_t": 32, "int64_t": 64, "uint64_t": 64}


def _reference(decoder: MavlinkDecoder, msg: object) -> bytes | None:
    view = decoder.view(msg)
    return None if view is None else dumps(view[2])


@pytest.mark.parametrize("path", GOLDEN, ids=[p.name for p in GOLDEN])
def test_every_golden_frame(path: Path) -> None:
    decoder = MavlinkDecoder()
    n = 0
    with RecordingReader(path) as reader:
        for message in reader.messages([MAVLINK_RAW]):
            _, frame = rawframe.decode(message.data)
            msg = decoder._mav.decode(bytearray(frame))
            made = decoder.json(msg)
            assert made is not None
            assert made[2] == _reference(decoder, msg), msg.get_type()
            assert decoder.decode_json(frame) == made
            n += 1
    assert n > 10_000


def _value(rng: random.Random, ftype: str, length: int, awkward: bool) -> object:
    if ftype == "char":
        return bytes(rng.choice(_TEXT) for _ in range(rng.randint(0, length)))
    if ftype in ("float", "double"):
        pick = (
            (lambda: rng.choice(_FLOATS))
            if awkward
            else (lambda: struct.unpack("<f", struct.pack("<f", rng.uniform(-1e4, 1e4)))[0])
        )
        return [pick() for _ in range(length)] if length else pick()
    bits = _INTS[ftype]
    signed = ftype[0] == "i"
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    pick_int = lambda: rng.choice([lo, hi, 0, rng.randint(lo, hi)])  # noqa: E731
    return [pick_int() for _ in range(length)] if length else pick_int()


@pytest.mark.parametrize("awkward", [False, True])
def test_every_message_type(awkward: bool) -> None:
    decoder = MavlinkDecoder()
    module = dialect_module("ardupilotmega")
    mav = module.MAVLink(None, srcSystem=7, srcComponent=42)
    rng = random.Random(29)
    checked = 0
    for _ in range(3):
        for cls in module.mavlink_map.values():
            lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
            args = [
                _value(rng, ftype, lengths[name], awkward)
                for name, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)
            ]
            frame = bytes(cls(*args).pack(mav))
            msg = decoder._mav.decode(bytearray(frame))
            made = decoder.json(msg)
            assert made is not None and made[2] == _reference(decoder, msg), cls.msgname
            checked += 1
    assert checked > 600


def test_an_unknown_id_has_no_view() -> None:
    decoder = MavlinkDecoder()
    msg = decoder._mav.heartbeat_encode(2, 3, 0, 0, 4)
    msg._header.msgId = 0xFFFFFF  # an id the dialect does not have
    assert decoder.json(msg) is None and decoder.view(msg) is None
