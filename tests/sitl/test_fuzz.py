"""Garbage on the link never crashes the vehicle or stops it serving others."""

from __future__ import annotations

import math
import random
import socket

from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.mavlink import new_encoder
from uavtool.sitl import Sitl, SitlConfig

N_FRAMES = 100_000


def _valid_frames(rng: random.Random, enc: object) -> list[bytes]:
    """A pool of real frames, some addressed to us with hostile values, some to others."""
    nan, inf = math.nan, math.inf
    msgs = [
        M.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3),
        M.MAVLink_command_long_message(42, 1, 400, 0, 1, 21196, 0, 0, 0, 0, 0),  # other system
        M.MAVLink_command_long_message(1, 77, 400, 0, 1, 21196, 0, 0, 0, 0, 0),  # other component
        M.MAVLink_command_long_message(1, 1, M.MAV_CMD_CONDITION_YAW, 0, nan, inf, 0, 0, 0, 0, 0),
        M.MAVLink_command_long_message(1, 1, M.MAV_CMD_DO_CHANGE_SPEED, 0, 1, nan, 0, 0, 0, 0, 0),
        M.MAVLink_command_long_message(1, 1, M.MAV_CMD_REQUEST_MESSAGE, 0, 1e30, 0, 0, 0, 0, 0, 0),
        M.MAVLink_command_long_message(
            1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, -5, 1e-9, 0, 0, 0, 0, 0
        ),
        M.MAVLink_command_int_message(
            1, 1, 200, M.MAV_CMD_DO_REPOSITION, 0, 0, -1, 0, 0, nan, 2**31 - 1, -(2**31), inf
        ),
        M.MAVLink_param_set_message(1, 1, b"WPNAV_SPEED", nan, 9),
        M.MAVLink_param_set_message(1, 1, b"\xff\xfe", 1, 9),
        M.MAVLink_param_request_read_message(1, 1, b"", 30000),
        M.MAVLink_set_position_target_local_ned_message(
            0, 1, 1, 1, 0, nan, inf, -inf, 0, 0, 0, 0, 0, 0, nan, 0
        ),
        M.MAVLink_set_position_target_global_int_message(
            0, 1, 1, 99, 0, 1, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0
        ),
        M.MAVLink_gimbal_manager_set_attitude_message(1, 1, 0, 0, [inf, nan, 0, 0], 0, 0, 0),
        M.MAVLink_mission_item_int_message(
            1, 1, 5, 0, 16, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0
        ),  # no transfer open
        M.MAVLink_mission_request_int_message(1, 1, 65535, 0),
        M.MAVLink_mission_count_message(1, 1, 2, 255),
        M.MAVLink_request_data_stream_message(1, 1, 255, 65535, 1),
        M.MAVLink_file_transfer_protocol_message(0, 1, 1, [rng.randrange(256) for _ in range(251)]),
    ]
    return [m.pack(enc) for m in msgs]


def _malformed(rng: random.Random, pool: list[bytes]) -> bytes:
    kind = rng.randrange(6)
    frame = bytearray(rng.choice(pool))
    if kind == 0:  # random bytes, often containing start markers
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 40))) + b"\xfd"
    if kind == 1:  # bad CRC
        frame[-1] ^= 1 + rng.randrange(255)
        return bytes(frame)
    if kind == 2:  # truncated
        return bytes(frame[: rng.randrange(1, len(frame))])
    if kind == 3:  # wrong length byte
        frame[1] = rng.randrange(256)
        return bytes(frame)
    if kind == 4:  # unknown message id (CRC cannot match: no CRC_EXTRA known)
        frame[7:10] = rng.randrange(60000, 1 << 24).to_bytes(3, "little")
        return bytes(frame)
    return bytes(frame)  # a real frame with hostile field values


def test_100k_malformed_frames_then_normal_flight() -> None:
    rng = random.Random(1234)
    config = SitlConfig(endpoints=("tcpin:127.0.0.1:0", "udpin:127.0.0.1:0"), speedup=20)
    with Sitl(config) as sitl:
        good = Client.tcp(sitl.ports[0])
        good.wait_for("HEARTBEAT")
        pool = _valid_frames(rng, new_encoder(sysid=200, compid=1))
        blob = b"".join(_malformed(rng, pool) for _ in range(N_FRAMES))
        bad_tcp = socket.create_connection(("127.0.0.1", sitl.ports[0]))
        bad_udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        half = len(blob) // 2
        bad_tcp.sendall(blob[:half])
        for i in range(half, len(blob), 1024):
            bad_udp.sendto(blob[i : i + 1024], ("127.0.0.1", sitl.ports[1]))
            if i % 65536 == 0:
                good.pump(0)  # keep our own socket drained while the vehicle works
        good.wait_until(
            lambda c: sitl.rx_bytes >= half, timeout=60, what="vehicle to read all the garbage"
        )
        # The vehicle kept serving the good client while it chewed through the garbage.
        n_before = sum(1 for m in good.received if m.get_type() == "HEARTBEAT")
        good.pump(1.0)
        assert sum(1 for m in good.received if m.get_type() == "HEARTBEAT") > n_before
        bad_tcp.close()
        bad_udp.close()
        assert sitl.error is None
        # And it flies normally afterwards.
        good.takeoff(10)
        assert good.command(M.MAV_CMD_NAV_LAND).result == M.MAV_RESULT_ACCEPTED
        good.wait_until(
            lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
            what="landed",
        )
        assert good.alt_m() < 0.05
        good.close()
    assert sitl.error is None
