"""Stale telemetry: on a datagram link (UDP, a radio with retries, a MAVLink router) messages
arrive late and out of order. A late ``GLOBAL_POSITION_INT`` taken as the newest makes the
vehicle jump back in time, so every message that carries the sender's clock (``time_boot_ms``
or ``time_usec``) is compared with the newest of its kind from the same system and component,
and an older one is dropped. Messages without a timestamp (HEARTBEAT, COMMAND_ACK, …) pass.

A sender that reboots starts its clock again: time going back by more than
``reboot_back_s`` is taken as a reboot, not as lateness, and every stream of that sender starts
afresh. A link does not hold a datagram for seconds, while a rebooted vehicle's clock goes back
by its whole uptime; one that reboots within ``reboot_back_s`` of booting loses at most that
long of telemetry.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

_US_PER_MS = 1000


class FreshnessFilter:
    """Tells whether a received message is newer than what was already taken from its sender.

    ``dropped`` counts the stale messages, ``dropped_by_type`` per message name, ``reboots`` the
    times a sender's clock went back by more than ``reboot_back_s``."""

    def __init__(self, *, reboot_back_s: float = 5.0) -> None:
        if not reboot_back_s > 0:
            raise ValueError(f"reboot_back_s must be > 0, got {reboot_back_s}")
        self.reboot_back_us = round(reboot_back_s * 1e6)
        self.dropped = 0
        self.dropped_by_type: Counter[str] = Counter()
        self.reboots = 0
        # (system, component) -> message id -> newest timestamp taken, µs
        self._newest: dict[tuple[int, int], dict[int, int]] = {}

    def fresh(self, msg: Any) -> bool:
        """True if ``msg`` (a pymavlink message) is to be used; False if it is stale (counted)."""
        stamp_us = timestamp_us(msg)
        if stamp_us is None:
            return True
        source = (msg.get_srcSystem(), msg.get_srcComponent())
        streams = self._newest.setdefault(source, {})
        msgid = msg.get_msgId()
        newest_us = streams.get(msgid)
        if newest_us is not None and stamp_us < newest_us:
            if newest_us - stamp_us <= self.reboot_back_us:
                self.dropped += 1
                self.dropped_by_type[msg.get_type()] += 1
                return False
            self.reboots += 1
            streams.clear()  # the sender's clock started again: so did all its streams
        streams[msgid] = stamp_us
        return True


def timestamp_us(msg: Any) -> int | None:
    """The sender's clock in a message, µs (``time_boot_ms`` or ``time_usec``); None when the
    message has none or leaves it 0 (unknown, e.g. HOME_POSITION from many autopilots)."""
    fields = msg.fieldnames
    if "time_boot_ms" in fields:
        stamp = int(msg.time_boot_ms) * _US_PER_MS
    elif "time_usec" in fields:
        stamp = int(msg.time_usec)
    else:
        return None
    return stamp if stamp > 0 else None
