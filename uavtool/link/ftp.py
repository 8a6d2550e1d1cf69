"""Reading a file from the vehicle over MAVLink FTP (FILE_TRANSFER_PROTOCOL), as ground
stations fetch a component's metadata: open read-only, read it chunk by chunk, close. Each
request is sent again when its answer does not come (a lossy link may drop either)."""

from __future__ import annotations

import contextlib
import struct
from collections.abc import Callable

from uavtool.errors import LinkError
from uavtool.link.client import VehicleLink
from uavtool.mavlink.dialect import mavlink as M

_TERMINATE, _OPEN_RO, _READ = 1, 4, 5
_ACK, _NAK = 128, 129
_EOF = 6  # NAK error code: read past the end
_HEADER = struct.Struct("<HBBBBBxI")  # seq, session, opcode, size, req_opcode, burst, offset
_DATA_MAX = 239
MAX_FILE_BYTES = 8 << 20
"""Refuse larger files: metadata is tens of kilobytes; a vehicle claiming more is wrong."""


def read_file(
    link: VehicleLink,
    path: str,
    *,
    timeout_s: float = 3.0,
    retries: int = 5,
    on_wait: Callable[[], None] | None = None,
) -> bytes:
    """The whole file at ``path`` on the vehicle; LinkError if it does not answer (each
    request tried ``1 + retries`` times, ``timeout_s`` each on the link's clock) or refuses."""
    ftp = _Session(link, timeout_s, retries, on_wait)
    size = struct.unpack_from("<I", ftp.request(_OPEN_RO, 0, path.encode()[:_DATA_MAX]))[0]
    if size > MAX_FILE_BYTES:
        ftp.close()
        raise LinkError(
            f"{link.name}: MAVLink FTP: {path} is {size} bytes (at most {MAX_FILE_BYTES})"
        )
    data = bytearray()
    try:
        while len(data) < size:
            chunk = ftp.request(_READ, len(data), b"", size=min(_DATA_MAX, size - len(data)))
            if not chunk:
                break
            data += chunk
    finally:
        ftp.close()
    if len(data) != size:
        raise LinkError(f"{link.name}: MAVLink FTP: {path}: {len(data)} of {size} bytes read")
    return bytes(data)


class _Session:
    def __init__(
        self,
        link: VehicleLink,
        timeout_s: float,
        retries: int,
        on_wait: Callable[[], None] | None,
    ) -> None:
        self.link, self.timeout_s, self.retries, self.on_wait = link, timeout_s, retries, on_wait
        self.seq = 0
        self.session = 0

    def request(self, opcode: int, offset: int, data: bytes, *, size: int | None = None) -> bytes:
        """Send one request until its ACK (its data) or NAK (LinkError) arrives."""
        for _ in range(1 + self.retries):
            self.seq = (self.seq + 1) % 65536
            n = len(data) if size is None else size
            header = _HEADER.pack(self.seq, self.session, opcode, n, 0, 0, offset)
            payload = (header + data).ljust(251, b"\0")
            self.link.send(
                M.MAVLink_file_transfer_protocol_message(
                    0, self.link.target_system, self.link.target_component, list(payload)
                )
            )
            answer = self._answer(self.seq)
            if answer is None:
                continue
            _, session, code, length, _, _, _ = _HEADER.unpack_from(answer)
            body = answer[_HEADER.size : _HEADER.size + length]
            if code == _NAK:
                if opcode == _READ and body[:1] == bytes([_EOF]):
                    return b""
                error = body[0] if body else -1
                raise LinkError(
                    f"{self.link.name}: MAVLink FTP refused opcode {opcode}: error {error}"
                )
            if opcode == _OPEN_RO:
                self.session = session
            return body
        raise LinkError(
            f"{self.link.name}: no MAVLink FTP answer in {1 + self.retries} tries; does the "
            "vehicle serve MAVLink FTP?"
        )

    def _answer(self, seq: int) -> bytes | None:
        deadline = self.link.clock() + self.timeout_s
        while self.link.clock() < deadline:
            for msg in self.link.poll(0.05):
                if msg.get_type() != "FILE_TRANSFER_PROTOCOL":
                    continue
                payload = bytes(msg.payload)
                if _HEADER.unpack_from(payload)[0] == (seq + 1) % 65536:  # answers seq + 1
                    return payload
            if self.on_wait is not None:
                self.on_wait()
        return None

    def close(self) -> None:
        with contextlib.suppress(LinkError):  # best effort: the vehicle frees idle sessions
            self.request(_TERMINATE, 0, b"")
