"""A fake PX4 on the far end of a VehicleLink: it answers what the autopilot adapters ask
(REQUEST_MESSAGE for COMPONENT_METADATA, MAVLink FTP reads) from files in memory, and keeps
every message the ground station sent. Optionally drops its first answers (a lossy link)."""

from __future__ import annotations

import lzma
import struct
from collections.abc import Callable
from typing import Any

from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mavlink.framing import FrameParser, new_encoder

_HEADER = struct.Struct("<HBBBBBxI")
INT_PARAMS = {"GF_ACTION", "MNT_MODE_IN", "MNT_MODE_OUT", "COM_ARM_WO_GPS"}
"""Parameters the fake keeps as INT32, as PX4 does; the others are REAL32."""


class FakePX4:
    name = "fake-px4"

    def __init__(
        self,
        files: dict[str, bytes],
        *,
        params: dict[str, float] | None = None,
        drop_first: int = 0,
    ) -> None:
        self.files = files
        self.params = params or {}
        self.sent: list[Any] = []  # what the ground station sent, decoded
        self._parser = FrameParser()
        self._enc = new_encoder(sysid=1, compid=1)
        self._out: list[bytes] = [self._pack(self._heartbeat()), self._pack(self._position())]
        self._drop = drop_first
        self._open: dict[int, bytes] = {}

    # --- Transport ------------------------------------------------------------------------

    def send(self, data: bytes) -> None:
        for frame in self._parser.feed(data):
            self.sent.append(frame.msg)
            self._answer(frame.msg)

    def recv(self, timeout_s: float) -> bytes:
        out, self._out = b"".join(self._out), []
        return out

    def close(self) -> None:
        pass

    # --- the vehicle ----------------------------------------------------------------------

    def _pack(self, msg: Any) -> bytes:
        raw = bytes(msg.pack(self._enc))
        self._enc.seq = (self._enc.seq + 1) % 256
        return raw

    def _heartbeat(self) -> Any:
        return M.MAVLink_heartbeat_message(
            M.MAV_TYPE_QUADROTOR, M.MAV_AUTOPILOT_PX4, 1, (4 << 16) | (3 << 24), 3, 3
        )

    def _position(self) -> Any:  # 2 m above home's 500 m, by the vehicle's reckoning
        return M.MAVLink_global_position_int_message(1000, 473977430, 85455970, 502_700, 2_000,
                                                     0, 0, 0, 9000)  # fmt: skip

    def _reply(self, msg: Any) -> None:
        if self._drop > 0:
            self._drop -= 1
            return
        self._out.append(self._pack(msg))

    def _answer(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "COMMAND_LONG" and msg.command == M.MAV_CMD_REQUEST_MESSAGE:
            if int(msg.param1) == M.MAVLINK_MSG_ID_COMPONENT_METADATA:
                uri = b"mftp://etc/extras/component_general.json.xz"
                self._reply(M.MAVLink_component_metadata_message(1000, 1, uri))
        elif kind in ("PARAM_REQUEST_READ", "PARAM_SET"):
            name = msg.param_id if isinstance(msg.param_id, str) else msg.param_id.decode()
            if name not in self.params:
                return
            is_int = name in INT_PARAMS
            if kind == "PARAM_SET":
                if msg.param_type != (
                    M.MAV_PARAM_TYPE_INT32 if is_int else M.MAV_PARAM_TYPE_REAL32
                ):
                    return  # PX4 ignores a PARAM_SET of the wrong type
                raw = struct.pack("<f", msg.param_value)
                self.params[name] = struct.unpack("<i", raw)[0] if is_int else msg.param_value
            value = self.params[name]
            if is_int:  # PX4's bytewise encoding: the int32's bytes in the float's place
                wire = struct.unpack("<f", struct.pack("<i", int(value)))[0]
                ptype = M.MAV_PARAM_TYPE_INT32
            else:
                wire, ptype = float(value), M.MAV_PARAM_TYPE_REAL32
            self._reply(M.MAVLink_param_value_message(name.encode(), wire, ptype, 1, 0))
        elif kind == "FILE_TRANSFER_PROTOCOL":
            self._ftp(bytes(msg.payload))

    def _ftp(self, payload: bytes) -> None:
        seq, session, opcode, size, _, _, offset = _HEADER.unpack_from(payload)
        data = payload[_HEADER.size : _HEADER.size + size]
        body, code = b"", 128
        if opcode == 4:  # OpenFileRO
            content = self.files.get(data.decode())
            if content is None:
                body, code = bytes([10]), 129  # FileNotFound
            else:
                session = len(self._open) + 1
                self._open[session] = content
                body = struct.pack("<I", len(content))
        elif opcode == 5:  # ReadFile
            content = self._open.get(session, b"")
            body = content[offset : offset + size]
            if not body:
                body, code = bytes([6]), 129  # EOF
        elif opcode == 1:  # TerminateSession
            self._open.pop(session, None)
        header = _HEADER.pack((seq + 1) % 65536, session, code, len(body), opcode, 0, offset)
        reply = (header + body).ljust(251, b"\0")
        self._reply(M.MAVLink_file_transfer_protocol_message(0, 255, 190, list(reply)))


def xz(data: bytes) -> bytes:
    return lzma.compress(data, format=lzma.FORMAT_XZ)


def link_to(fake: FakePX4, clock: Callable[[], float] | None = None) -> VehicleLink:
    """A link that has heard the fake vehicle (its heartbeat and position); its clock moves
    10 ms each time it is read, unless ``clock`` is given."""
    ticks = iter(range(10**9))
    link = VehicleLink(fake, clock=clock or (lambda: next(ticks) * 0.01), announce=False)
    link.poll(0.0)
    assert link.target_system == 1
    return link
