"""`packing.pack` makes the frames the built-in vehicle and the link send: they must be
pymavlink's own ``pack``, byte for byte, for every message type of the dialect, any values,
any sender and sequence; what pymavlink cannot pack, neither can it; a signing sender is
left to pymavlink."""

from __future__ import annotations

import random
import struct
from typing import Any

import pytest

from tests.mavlink.values import value
from uavtool.mavlink import mavlink, packing


def _filled(cls: Any, rng: random.Random, *, awkward: bool) -> Any:
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    args = [
        value(rng, ftype, lengths[name], awkward=awkward)
        for name, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)
    ]
    return cls(*args)


@pytest.mark.parametrize("awkward", [False, True])
def test_every_message_type_packs_as_pymavlink_packs_it(awkward: bool) -> None:
    rng = random.Random(29)
    checked = 0
    for _ in range(4):
        for cls in mavlink.mavlink_map.values():
            msg = _filled(cls, rng, awkward=awkward)
            sender = mavlink.MAVLink(
                None, srcSystem=rng.randrange(256), srcComponent=rng.randrange(256)
            )
            sender.seq = rng.randrange(256)
            theirs = bytes(msg.pack(sender))
            assert packing.pack(msg, sender) == theirs, cls.msgname
            checked += 1
    assert checked > 1200


def test_an_all_zero_payload_keeps_its_first_byte() -> None:
    msg = mavlink.MAVLink_heartbeat_message(0, 0, 0, 0, 0, 0)
    sender = mavlink.MAVLink(None)
    frame = packing.pack(msg, sender)
    assert frame == bytes(msg.pack(sender)) and frame[1] == 1


@pytest.mark.parametrize(
    ("msg", "error"),
    [
        (mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 300, 3), struct.error),  # 300 in a uint8
        (mavlink.MAVLink_attitude_message(0, "up", 0, 0, 0, 0, 0), struct.error),
        (mavlink.MAVLink_attitude_quaternion_message(0, 1, 0, 0, 0, 0, 0, 0, [0.0]), IndexError),
    ],
)
def test_what_pymavlink_cannot_pack_raises_as_it_raises(msg: Any, error: type) -> None:
    sender = mavlink.MAVLink(None)
    with pytest.raises(error):
        msg.pack(sender)
    with pytest.raises(error):
        packing.pack(msg, sender)


def test_a_signing_sender_signs_as_pymavlink_does() -> None:
    ours, theirs = (mavlink.MAVLink(None, srcSystem=1, srcComponent=1) for _ in range(2))
    for mav in (ours, theirs):
        mav.signing.secret_key = bytes(range(32))
        mav.signing.sign_outgoing = True
        mav.signing.timestamp = 1234
    msg = mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3)
    frame = packing.pack(msg, ours)
    assert frame == bytes(msg.pack(theirs)) and frame[2] & mavlink.MAVLINK_IFLAG_SIGNED
