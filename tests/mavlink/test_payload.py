"""`FrameParser` builds the message of an unsigned MAVLink 2 frame itself (`payload`), and
`MavlinkDecoder.decode_json` writes its JSON view from the same layout: the message must be
pymavlink's own, attribute for attribute, for every message type of the dialect, every
golden frame, and frames signed, in MAVLink 1, cut, lengthened or with any byte changed."""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from tests.mavlink.values import every_message, variants
from uavtool.mavlink import FrameParser, mavlink
from uavtool.recording import RecordingReader, rawframe
from uavtool.recording.schemas import MAVLINK_RAW

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


def _by_pymavlink(frame: bytes) -> Any:
    """What `FrameParser` made of a frame before: pymavlink's decode, after refusing flags
    it does not know."""
    if frame[0] == 0xFD and frame[2] & ~mavlink.MAVLINK_IFLAG_SIGNED:
        return None
    try:
        msg = mavlink.MAVLink(None).decode(bytearray(frame))
    except (mavlink.MAVError, ValueError, IndexError, TypeError):
        return None
    return None if isinstance(msg, mavlink.MAVLink_unknown) else msg


def _same(ours: Any, theirs: Any) -> bool:
    """The same class and attributes (floats by repr: NaN is NaN), header included."""
    if ours is None or theirs is None:
        return ours is theirs
    a, b = dict(vars(ours)), dict(vars(theirs))
    head_a, head_b = vars(a.pop("_header")), vars(b.pop("_header"))
    return (
        type(ours) is type(theirs)
        and repr(sorted(a.items())) == repr(sorted(b.items()))
        and head_a == head_b
    )


def _decoded(frame: bytes) -> Any:
    got = FrameParser()._decode(frame)
    return None if got is None else got.msg


def test_every_message_type_is_pymavlinks_message() -> None:
    checked = 0
    for cls, frame in every_message(mavlink, random.Random(26), 4, awkward=True):
        ours, theirs = _decoded(frame), _by_pymavlink(frame)
        assert theirs is not None and _same(ours, theirs), cls.msgname
        checked += 1
    assert checked > 800


@pytest.mark.parametrize("path", GOLDEN[:2], ids=[p.name for p in GOLDEN[:2]])
def test_golden_frames_and_their_variants_decode_as_pymavlink_decodes_them(path: Path) -> None:
    rng = random.Random(path.name)
    signer = mavlink.MAVLink(None, srcSystem=3, srcComponent=1)
    signer.signing.secret_key = bytes(range(32))
    signer.signing.sign_outgoing = True
    v1 = mavlink.MAVLink(None, srcSystem=3, srcComponent=1)
    one_of_each: dict[int, bytes] = {}
    with RecordingReader(path) as reader:
        for message in reader.messages([MAVLINK_RAW]):
            frame = rawframe.decode(message.data)[1]
            assert _same(_decoded(frame), _by_pymavlink(frame))
            one_of_each.setdefault(int.from_bytes(frame[7:10], "little"), frame)
    checked = 0
    for frame in one_of_each.values():
        for variant in variants(frame, _by_pymavlink(frame), signer, v1, rng):
            assert _same(_decoded(variant), _by_pymavlink(variant)), variant
            checked += 1
    assert len(one_of_each) > 20 and checked > 1200


def test_a_parser_with_a_signing_key_leaves_unsigned_frames_to_pymavlink() -> None:
    """pymavlink counts the unsigned frames a signing link accepts; so does the parser."""
    frame = bytes(mavlink.MAVLink(None).heartbeat_encode(2, 3, 0, 0, 4).pack(mavlink.MAVLink(None)))
    for key in (bytes(32), b""):
        parser = FrameParser(signing_key=key)
        got = parser._decode(frame)
        assert got is not None and not got.signed
        assert parser._mav.signing.unsigned_count == 1
