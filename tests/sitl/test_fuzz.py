"""Garbage on the link never crashes the vehicle or stops it serving others; nor do
well-formed frames with hostile values (NaN, ±∞, extremes) for every command and message."""

from __future__ import annotations

import math
import random
import socket
from collections import Counter
from typing import Any

from hypothesis import event, given, settings
from hypothesis import strategies as st

from tests.fuzzing import examples
from tests.sitl.client import Client
from tests.sitl.pilot import Pilot
from uavtool.mavlink import mavlink as M
from uavtool.mavlink import new_encoder
from uavtool.mavlink.fields import INT_RANGES
from uavtool.sitl import Sitl, SitlConfig
from uavtool.sitl.commands import HANDLERS
from uavtool.sitl.params import PARAM_SPECS

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


# --------------------------------------------------------------------------------------------
# Well-formed frames with hostile values: every command id, every message the vehicle acts on.

_F32_MAX = 3.4028234663852886e38
HOSTILE_FLOATS = (
    math.nan,
    math.inf,
    -math.inf,
    _F32_MAX,
    -_F32_MAX,
    1e-45,
    -0.0,
    0.0,
    1.0,
    -1.0,
    -2.0,
    -3.0,
    300.0,
    65536.0,
    2.0**31,
    -(2.0**31),
    2.0**32,
)
ALL_COMMANDS = tuple(sorted(M.enums["MAV_CMD"]))
HANDLED_COMMANDS = tuple(sorted(HANDLERS))


def _settable_types() -> tuple[str, ...]:
    """Every message type the vehicle's session acts on."""
    pilot = Pilot()
    return tuple(sorted(pilot.link.session._handlers))


SETTABLE = _settable_types()


def _message_class(name: str) -> Any:
    return getattr(M, f"MAVLink_{name.lower()}_message")


def _floats() -> st.SearchStrategy[float]:
    return st.one_of(st.sampled_from(HOSTILE_FLOATS), st.floats(width=32))


def _field(name: str, ftype: str, length: int) -> st.SearchStrategy[Any]:
    if name in ("target_system", "target_component"):
        return st.sampled_from([0, 1, 1, 1, 255])  # mostly addressed to us
    if name == "param_id":
        names = [s.name.encode() for s in PARAM_SPECS]
        return st.one_of(st.sampled_from(names), st.binary(max_size=16))
    if name == "command":  # mostly the ones the vehicle implements: those have handlers to break
        return st.one_of(
            st.sampled_from(HANDLED_COMMANDS),
            st.sampled_from(HANDLED_COMMANDS),
            st.sampled_from(ALL_COMMANDS),
            st.integers(0, 2**16 - 1),
        )
    if ftype == "char":
        return st.binary(max_size=length)
    if ftype in ("float", "double"):
        scalar = _floats()
    else:
        low, high = INT_RANGES[ftype]
        scalar = st.one_of(st.sampled_from([low, high, 0, 1]), st.integers(low, high))
    return st.lists(scalar, min_size=length, max_size=length) if length else scalar


@st.composite
def hostile_messages(draw: st.DrawFn) -> Any:
    name = draw(
        st.one_of(st.sampled_from(("COMMAND_LONG", "COMMAND_INT")), st.sampled_from(SETTABLE))
    )
    cls = _message_class(name)
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    values = [
        draw(_field(fname, ftype, lengths[fname]))
        for fname, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)
    ]
    return cls(*values)


def _addressed_command(msg: Any) -> int | None:
    if msg.get_type() not in ("COMMAND_LONG", "COMMAND_INT"):
        return None
    if msg.target_system not in (0, 1) or msg.target_component not in (0, 1):
        return None
    return int(msg.command)


@st.composite
def hostile_commands(draw: st.DrawFn) -> Any:
    """COMMAND_LONG or COMMAND_INT, addressed to the vehicle, with hostile params."""
    command = draw(st.one_of(st.sampled_from(HANDLED_COMMANDS), st.sampled_from(ALL_COMMANDS)))
    p = draw(st.lists(_floats(), min_size=7, max_size=7))
    if draw(st.booleans()):
        return M.MAVLink_command_long_message(1, 1, command, 0, *p)
    frame = draw(st.integers(0, 255))
    x, y = draw(st.tuples(_field("x", "int32_t", 0), _field("y", "int32_t", 0)))
    return M.MAVLink_command_int_message(1, 1, frame, command, 0, 0, *p[:4], x, y, p[6])


@settings(max_examples=examples(400), deadline=None, derandomize=True, database=None)
@given(st.lists(hostile_commands(), min_size=1, max_size=8))
def test_hostile_command_params_are_refused_with_one_ack_each(msgs: list[Any]) -> None:
    pilot = Pilot()
    for msg in msgs:
        pilot.send(msg)
    pilot.run(1.1)  # every stream sent at least once since: telemetry must still pack
    assert pilot.sitl.faults == 0
    assert pilot.link.unsendable == 0
    acked = Counter(int(m.command) for m in pilot.of_type("COMMAND_ACK"))
    assert acked == Counter(int(m.command) for m in msgs)
    refused = [m for m in pilot.of_type("COMMAND_ACK") if m.result == M.MAV_RESULT_DENIED]
    assert len(pilot.statustexts()) >= len(refused)  # each refusal says why


FUZZ_STATS: Counter[str] = Counter()


@settings(max_examples=examples(120), deadline=None, derandomize=True, database=None)
@given(st.lists(hostile_messages(), min_size=1, max_size=40))
def test_hostile_values_are_refused_and_the_vehicle_still_flies(msgs: list[Any]) -> None:
    pilot = Pilot()
    sent: Counter[int] = Counter()
    for msg in msgs:
        pilot.send(msg)
        cmd = _addressed_command(msg)
        if cmd is not None:
            sent[cmd] += 1
        pilot.run(0.02)  # one physics step between frames
        FUZZ_STATS[msg.get_type()] += 1
    pilot.run(
        1.1
    )  # Every handler checked its arguments: nothing reached the fault net, nothing outgoing
    # failed to pack, and every command addressed to us got exactly one COMMAND_ACK.
    assert pilot.sitl.faults == 0
    assert pilot.link.unsendable == 0
    assert not pilot.link.closed
    acked = Counter(int(m.command) for m in pilot.of_type("COMMAND_ACK"))
    for cmd, count in sent.items():
        assert acked[cmd] >= count, f"command {cmd}: {count} sent, {acked[cmd]} ACKs"
    pilot.recover()
    if pilot.sitl.crashed:  # hostile but legal: e.g. a fast descent into the ground
        event("crashed")
        ack = pilot.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        assert ack.result == M.MAV_RESULT_FAILED
        return
    pilot.normal_flight()
    assert pilot.sitl.faults == 0
    assert pilot.link.unsendable == 0


def test_every_command_id_with_extreme_params_then_a_normal_flight() -> None:
    pilot = Pilot()
    patterns = [(v,) * 7 for v in HOSTILE_FLOATS] + [
        (math.nan, math.inf, -math.inf, _F32_MAX, -_F32_MAX, 1e-45, 300.0)
    ]
    n = 0
    for command in ALL_COMMANDS:
        for params in patterns:
            if params[1] == 21196:  # a forced disarm in flight is a crash, by design
                continue
            pilot.send(M.MAVLink_command_long_message(1, 1, command, 0, *params))
            x, y = (2**31 - 1, -(2**31)) if n % 2 else (0, 0)
            pilot.send(
                M.MAVLink_command_int_message(
                    1, 1, n % 40, command, 0, 0, *params[:4], x, y, params[6]
                )
            )
            n += 2
        pilot.run(0.02)
    acks = Counter(int(m.command) for m in pilot.of_type("COMMAND_ACK"))
    assert all(acks[c] == 2 * len(patterns) for c in ALL_COMMANDS)
    assert pilot.sitl.faults == 0
    assert pilot.link.unsendable == 0
    assert n == 2 * len(ALL_COMMANDS) * len(patterns)  # 6,834 commands
    pilot.recover()
    pilot.normal_flight(10.0)


def test_gimbal_configure_300_is_denied_and_the_vehicle_goes_on(client: Client) -> None:
    """The crash of issue 19: an echoed controller id of 300 does not fit GIMBAL_MANAGER_STATUS."""
    ack = client.command(M.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE, 300)
    assert ack.result == M.MAV_RESULT_DENIED
    assert "Gimbal" in client.reason()
    status = client.wait_for("GIMBAL_MANAGER_STATUS", timeout=3)
    assert status.primary_control_sysid == 0
    assert client.command(M.MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE, -2).result == M.MAV_RESULT_ACCEPTED
    client.wait_for(
        "GIMBAL_MANAGER_STATUS",
        lambda m: (m.primary_control_sysid, m.primary_control_compid) == (255, 190),
        timeout=3,
    )
