"""The JSON view of a MAVLink message as the writer makes it (`MavlinkDecoder.json`: one
generated template per message type) is byte for byte what ``dumps(view(msg))`` writes (the
dict the null rule describes, through `json`): for every frame of every golden, and for
every message type of the dialect filled with awkward values (NaN, infinities, -0.0, floats
whose sum overflows, quotes, backslashes, '%' and control characters in text)."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from tests.mavlink.values import every_message, variants
from uavtool.recording import RecordingReader, rawframe
from uavtool.recording.schemas import MAVLINK_RAW, MavlinkDecoder, dialect_module, dumps

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


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


@pytest.mark.parametrize("awkward", [False, True])
def test_every_message_type(awkward: bool) -> None:
    decoder = MavlinkDecoder()
    module = dialect_module("ardupilotmega")
    checked = 0
    for cls, frame in every_message(module, random.Random(29), 3, awkward=awkward):
        msg = decoder._mav.decode(bytearray(frame))
        made = decoder.json(msg)
        assert made is not None and made[2] == _reference(decoder, msg), cls.msgname
        assert decoder.decode_json(frame) == made, cls.msgname  # without pymavlink's
        checked += 1
    assert checked > 600


def _by_pymavlink(decoder: MavlinkDecoder, frame: bytes) -> tuple[int, str, bytes] | None:
    """`decode_json` as it was: pymavlink decodes the frame into a message, then its view."""
    try:
        msg = dialect_module("ardupilotmega").MAVLink(None).decode(bytearray(frame))
    except (dialect_module("ardupilotmega").MAVError, IndexError, ValueError):
        return None
    return decoder.json(msg)


def test_frames_decoded_without_pymavlink_are_as_pymavlink_decodes_them() -> None:
    """`decode_json` takes unsigned MAVLink 2 frames apart itself: each golden frame's type
    with one byte changed anywhere (a bad CRC is no view; a length that does not add up, an
    unknown id, a flag), cut short, signed or in MAVLink 1 gives what pymavlink's decoding
    does."""
    decoder = MavlinkDecoder()
    module = dialect_module("ardupilotmega")
    rng = random.Random(2929)
    frames: dict[int, bytes] = {}
    for path in GOLDEN[:2]:
        with RecordingReader(path) as reader:
            for message in reader.messages([MAVLINK_RAW]):
                frame = rawframe.decode(message.data)[1]
                frames.setdefault(int.from_bytes(frame[7:10], "little"), frame)
    signer = module.MAVLink(None, srcSystem=3, srcComponent=1)
    signer.signing.secret_key = bytes(range(32))
    signer.signing.sign_outgoing = True
    v1 = module.MAVLink(None, srcSystem=3, srcComponent=1)
    v1.WIRE_PROTOCOL_VERSION = "1.0"
    checked = 0
    for frame in frames.values():
        msg = decoder._mav.decode(bytearray(frame))
        for variant in [frame, *variants(frame, msg, signer, v1, rng)]:
            assert decoder.decode_json(variant) == _by_pymavlink(decoder, variant), variant
            checked += 1
    assert len(frames) > 20 and checked > 1000


def test_an_unknown_id_has_no_view() -> None:
    decoder = MavlinkDecoder()
    msg = decoder._mav.heartbeat_encode(2, 3, 0, 0, 4)
    msg._header.msgId = 0xFFFFFF  # an id the dialect does not have
    assert decoder.json(msg) is None and decoder.view(msg) is None
