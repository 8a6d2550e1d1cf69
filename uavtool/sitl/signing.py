"""MAVLink 2 signing, vehicle side: which signed frames to believe.

The signature is checked first; only a frame whose signature verifies moves its stream's
timestamp forward. A stream is (system id, component id, link id) and its last timestamp is
kept for the whole vehicle, not per connection, as ArduPilot keeps its signing streams: a
signed frame captured on one link and replayed on a new TCP connection or from a new UDP
port carries a timestamp the vehicle has already seen, and is refused. A forged frame with
a huge timestamp and a bad signature changes nothing, so it cannot lock a ground station out.
A new stream is accepted only if its timestamp is at most a minute behind the newest time
the vehicle knows, and at most ``MAX_STREAMS`` streams are kept (MAVLINK_MAX_SIGNING_STREAMS).

Timestamps count 10 µs since 2015-01-01 (the MAVLink signing epoch).
"""

from __future__ import annotations

import hashlib
import hmac
from collections.abc import Callable

from uavtool.mavlink.dialect import mavlink

MAX_STREAMS = 16
NEW_STREAM_MAX_AGE = 6_000_000
"""A new stream's first timestamp may lag the vehicle's newest time by at most one minute."""
SIGNING_EPOCH_UNIX_US = 1_420_070_400_000_000
_STX_V2 = 0xFD
_SIGNED = mavlink.MAVLINK_IFLAG_SIGNED
_BLOCK = mavlink.MAVLINK_SIGNATURE_BLOCK_LEN  # link id (1), timestamp (6), signature (6)

StreamKey = tuple[int, int, int]  # (system id, component id, link id)


class SigningStreams:
    """The signing key and every stream's newest verified timestamp, for one vehicle.

    ``unix_us`` reads the real time (µs since 1970), as ArduPilot's signing time follows
    GPS time: never the simulation's clock, which runs ahead of ground stations' clocks at
    a speed-up above 1 and would refuse every new stream after a minute's lead. The time
    never goes backwards, even when ``unix_us`` does.
    """

    def __init__(self, key: bytes, *, unix_us: Callable[[], int]) -> None:
        self._key = key
        self._unix_us = unix_us
        self._newest = 0
        self.streams: dict[StreamKey, int] = {}
        self.refused = 0

    def now(self) -> int:
        """The newest time the vehicle knows: its clock, or a verified timestamp ahead of it."""
        clock = (self._unix_us() - SIGNING_EPOCH_UNIX_US) // 10
        self._newest = max(self._newest, clock)
        return self._newest

    def verify(self, raw: bytes) -> bool:
        """True if ``raw`` (one whole MAVLink frame) is signed with our key and is no replay."""
        if len(raw) < 12 + _BLOCK or raw[0] != _STX_V2 or not raw[2] & _SIGNED:
            return False
        expected = hashlib.sha256(self._key + raw[:-6]).digest()[:6]
        if not hmac.compare_digest(expected, raw[-6:]):
            return self._refuse()
        timestamp = int.from_bytes(raw[-12:-6], "little")
        stream = (raw[5], raw[6], raw[-13])
        last = self.streams.get(stream)
        if last is None:
            if len(self.streams) >= MAX_STREAMS or timestamp + NEW_STREAM_MAX_AGE < self.now():
                return self._refuse()
        elif timestamp <= last:
            return self._refuse()
        self.streams[stream] = timestamp
        self._newest = max(self._newest, timestamp)
        return True

    def _refuse(self) -> bool:
        self.refused += 1
        return False
