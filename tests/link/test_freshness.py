"""Stale telemetry is dropped per sender and message type, before anyone uses it; the tap (the
recording) still hears every frame; a rebooted vehicle is followed, not ignored."""

from __future__ import annotations

from typing import Any

import pytest

from uavtool.link import VehicleLink
from uavtool.link.freshness import FreshnessFilter, timestamp_us
from uavtool.mavlink import FrameParser, new_encoder
from uavtool.mavlink import mavlink as M


def _frame(msg: Any, *, sysid: int = 1, compid: int = 1) -> bytes:
    return bytes(msg.pack(new_encoder(sysid=sysid, compid=compid)))


def _decoded(msg: Any, *, sysid: int = 1, compid: int = 1) -> Any:
    (frame,) = FrameParser().feed(_frame(msg, sysid=sysid, compid=compid))
    return frame.msg


def _position(t_ms: int) -> Any:
    return M.MAVLink_global_position_int_message(t_ms, 0, 0, 0, 0, 0, 0, 0, 0)


def _attitude(t_ms: int) -> Any:
    return M.MAVLink_attitude_message(t_ms, 0, 0, 0, 0, 0, 0)


def _heartbeat() -> Any:
    return M.MAVLink_heartbeat_message(
        M.MAV_TYPE_QUADROTOR, M.MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 4, M.MAV_STATE_ACTIVE, 3
    )


def test_an_older_message_of_the_same_kind_is_dropped_and_counted() -> None:
    f = FreshnessFilter()
    taken = [f.fresh(_decoded(_position(t))) for t in (100, 300, 200, 300, 400, 150)]
    assert taken == [True, True, False, True, True, False]  # equal is not older
    assert f.dropped == 2 and f.dropped_by_type == {"GLOBAL_POSITION_INT": 2}
    assert f.reboots == 0


def test_each_message_type_and_each_sender_has_its_own_clock() -> None:
    f = FreshnessFilter()
    assert f.fresh(_decoded(_position(5000)))
    assert f.fresh(_decoded(_attitude(4000)))  # another type: not compared with positions
    assert f.fresh(_decoded(_position(4000), compid=154))  # another component
    assert f.fresh(_decoded(_position(4000), sysid=2))  # another vehicle
    assert not f.fresh(_decoded(_position(4999)))
    assert f.dropped == 1


def test_messages_without_a_clock_always_pass() -> None:
    f = FreshnessFilter()
    assert timestamp_us(_decoded(_heartbeat())) is None
    assert all(f.fresh(_decoded(_heartbeat())) for _ in range(3))
    home = M.MAVLink_home_position_message(1, 2, 3, 0, 0, 0, [1, 0, 0, 0], 0, 0, 0, 0)
    assert timestamp_us(_decoded(home)) is None  # time_usec 0: unknown
    assert f.fresh(_decoded(home)) and f.dropped == 0


def test_time_usec_is_the_clock_where_there_is_no_time_boot_ms() -> None:
    f = FreshnessFilter()
    raw = M.MAVLink_gps_raw_int_message(2_000_000, 3, 0, 0, 0, 0, 0, 0, 0, 10)
    assert timestamp_us(_decoded(raw)) == 2_000_000
    older = M.MAVLink_gps_raw_int_message(1_900_000, 3, 0, 0, 0, 0, 0, 0, 0, 10)
    assert f.fresh(_decoded(raw)) and not f.fresh(_decoded(older))


def test_a_reboot_starts_every_stream_of_that_sender_afresh() -> None:
    f = FreshnessFilter(reboot_back_s=5.0)
    assert f.fresh(_decoded(_position(600_000)))
    assert f.fresh(_decoded(_attitude(600_000)))
    assert f.fresh(_decoded(_position(2_000_000), sysid=2))
    assert not f.fresh(_decoded(_position(596_000)))  # 4 s late: a very late datagram
    assert f.fresh(_decoded(_position(1_500)))  # 598 s back: the vehicle rebooted
    assert f.fresh(_decoded(_attitude(1_400)))  # so did its attitude stream
    assert f.fresh(_decoded(_position(1_600)))
    assert not f.fresh(_decoded(_position(1_550)))
    assert not f.fresh(_decoded(_position(1_999_000), sysid=2))  # the other vehicle did not
    assert f.reboots == 1 and f.dropped == 3


def test_reboot_threshold_must_be_positive() -> None:
    with pytest.raises(ValueError, match="reboot_back_s"):
        FreshnessFilter(reboot_back_s=0.0)


class _Scripted:
    """A transport that delivers one scripted datagram per ``recv``."""

    name = "scripted"

    def __init__(self, datagrams: list[bytes]) -> None:
        self.datagrams = datagrams
        self.sent: list[bytes] = []

    def send(self, data: bytes) -> None:
        self.sent.append(data)

    def recv(self, timeout_s: float) -> bytes:
        return self.datagrams.pop(0) if self.datagrams else b""

    def close(self) -> None:
        pass


def test_the_link_hands_on_only_fresh_messages_and_taps_every_frame() -> None:
    """Reordered datagrams: the state never goes back in time, the recording keeps all."""
    order = [1000, 1200, 1100, 1300, 900]  # time_boot_ms as they arrive
    datagrams = [_frame(_heartbeat())] + [_frame(_position(t)) for t in order]
    tapped: list[bytes] = []
    link = VehicleLink(_Scripted(list(datagrams)), tap=lambda _d, raws, _msgs: tapped.extend(raws))
    seen: list[int] = []
    for _ in datagrams:
        for msg in link.poll(0.0):
            if msg.get_type() == "GLOBAL_POSITION_INT":
                seen.append(msg.time_boot_ms)
                assert link.state.position.time_boot_ms == msg.time_boot_ms
    assert seen == [1000, 1200, 1300]
    assert link.state.position.time_boot_ms == 1300
    assert tapped == datagrams  # everything as received, stale frames included
    assert link.freshness.dropped == 2
