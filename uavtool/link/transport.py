"""Byte transports to a vehicle, chosen by connection string (pymavlink's spelling):

``tcp:HOST:PORT`` (connect), ``udpin:HOST:PORT`` (listen; ``udp:`` is the same),
``udpout:HOST:PORT`` (send first), ``serial:DEVICE[:BAUD]`` or a bare ``/dev/…`` path.
"""

from __future__ import annotations

import contextlib
import errno
import socket
import time
from collections.abc import Callable
from typing import Any, Protocol

from uavtool.errors import LinkError

_UDP_MAX = 65535
UDP_RECEIVE_BYTES = 4 << 20
"""The receive buffer a recorder's UDP link asks for (the default, ~200 KiB, is ~2 s of a
fleet's streams)."""
_DEFAULT_BAUD = 57600


class Transport(Protocol):
    """A bidirectional byte pipe. ``recv`` returns b"" when nothing arrived in time."""

    name: str

    def send(self, data: bytes) -> None: ...

    def recv(self, timeout_s: float) -> bytes: ...

    def close(self) -> None: ...


class TcpTransport:
    def __init__(
        self,
        host: str,
        port: int,
        *,
        connect_timeout_s: float = 10.0,
        waiting: Callable[[str], None] | None = None,
    ) -> None:
        self.name = f"tcp:{host}:{port}"
        deadline = time.monotonic() + connect_timeout_s
        told = False
        while True:  # a vehicle that is still starting refuses for a moment
            try:
                self.sock = socket.create_connection((host, port), timeout=2.0)
                break
            except OSError as exc:
                if time.monotonic() > deadline:
                    raise LinkError(f"{self.name}: cannot connect: {_why(exc)}") from None
                if waiting is not None and not told:  # say so now, not after the timeout
                    waiting(
                        f"{self.name}: {_why(exc)}; trying again for up to "
                        f"{connect_timeout_s:g} s (is the vehicle running? Ctrl-C stops)"
                    )
                    told = True
                time.sleep(0.2)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def send(self, data: bytes) -> None:
        try:
            self.sock.sendall(data)
        except OSError as exc:
            raise LinkError(f"{self.name}: send failed: {_why(exc)}") from None

    def recv(self, timeout_s: float) -> bytes:
        self.sock.settimeout(max(timeout_s, 0.0))
        try:
            data = self.sock.recv(_UDP_MAX)
        except (TimeoutError, BlockingIOError):
            return b""
        except OSError as exc:
            raise LinkError(f"{self.name}: receive failed: {_why(exc)}") from None
        if not data:
            raise LinkError(f"{self.name}: the vehicle closed the connection")
        return data

    def close(self) -> None:
        self.sock.close()


class UdpTransport:
    """``udpin`` binds and answers whoever spoke last; ``udpout`` sends to a fixed address."""

    def __init__(
        self, host: str, port: int, *, listen: bool, receive_bytes: int | None = None
    ) -> None:
        self.name = f"{'udpin' if listen else 'udpout'}:{host}:{port}"
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.peer: tuple[str, int] | None = None
        if receive_bytes is not None:  # a recorder's: see open_transport's keep_all
            with contextlib.suppress(OSError):
                self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_bytes)
        try:
            if listen:
                self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                self.sock.bind((host, port))
            else:
                self.peer = (socket.gethostbyname(host), port)
        except OSError as exc:
            self.sock.close()
            raise LinkError(f"{self.name}: {_why(exc)}") from None

    def send(self, data: bytes) -> None:
        self.send_to(data, self.peer)

    def send_to(self, data: bytes, peer: tuple[str, int] | None) -> None:
        """Send to ``peer`` (on ``udpin``, one of those that spoke: several vehicles on one
        port); None: nobody has spoken yet, nothing is sent."""
        if peer is None:
            return
        try:
            self.sock.sendto(data, peer)
        except OSError as exc:
            if exc.errno not in (errno.ECONNREFUSED, errno.ENOBUFS):
                raise LinkError(f"{self.name}: send failed: {_why(exc)}") from None

    def recv(self, timeout_s: float) -> bytes:
        self.sock.settimeout(max(timeout_s, 0.0))
        try:
            data, addr = self.sock.recvfrom(_UDP_MAX)
        except (TimeoutError, BlockingIOError, ConnectionRefusedError):
            return b""
        except OSError as exc:
            raise LinkError(f"{self.name}: receive failed: {_why(exc)}") from None
        if self.name.startswith("udpin"):
            self.peer = addr
        return data

    def close(self) -> None:
        self.sock.close()


class SerialTransport:
    def __init__(self, device: str, baud: int) -> None:
        import serial  # type: ignore[import-untyped]  # noqa: PLC0415 - serial links only

        self.name = f"serial:{device}:{baud}"
        try:
            self.port: Any = serial.Serial(device, baud, timeout=0)
        except (serial.SerialException, ValueError) as exc:
            raise LinkError(f"{self.name}: {exc}") from None

    def send(self, data: bytes) -> None:
        try:
            self.port.write(data)
        except Exception as exc:  # serial raises SerialException or OSError
            raise LinkError(f"{self.name}: write failed: {exc}") from None

    def recv(self, timeout_s: float) -> bytes:
        self.port.timeout = max(timeout_s, 0.0)
        try:
            first = self.port.read(1)
            return bytes(first + self.port.read(self.port.in_waiting)) if first else b""
        except Exception as exc:  # device unplugged
            raise LinkError(f"{self.name}: read failed: {exc}") from None

    def close(self) -> None:
        self.port.close()


def open_transport(
    text: str,
    *,
    timeout_s: float = 10.0,
    waiting: Callable[[str], None] | None = None,
    keep_all: bool = False,
) -> Transport:
    """Open a connection string; raises LinkError naming what is wrong. A TCP vehicle that
    refuses is retried for ``timeout_s`` (it may still be starting); ``waiting`` hears that
    at the first refusal. ``keep_all`` (a recorder's link): a UDP socket keeps seconds of
    datagrams (`UDP_RECEIVE_BYTES`, capped by the kernel's net.core.rmem_max) for a reader
    held up on a busy machine, where a flight's link keeps the kernel's default: what a
    flight reads late is stale, and its lag stays short."""
    kind, _, rest = text.partition(":")
    if text.startswith("/dev/") or kind in ("serial", "com") or kind.upper().startswith("COM"):
        device, baud = _serial_parts(text)
        return SerialTransport(device, baud)
    opener = _OPENERS.get(kind)
    if opener is None:
        raise LinkError(
            f"connection {text!r}: expected tcp:HOST:PORT, udpin:HOST:PORT, udpout:HOST:PORT "
            "or serial:DEVICE[:BAUD]"
        )
    host, _, port_text = rest.rpartition(":")
    try:
        port = int(port_text)
    except ValueError:
        raise LinkError(f"connection {text!r}: port {port_text!r} is not a number") from None
    if not host or not 0 < port < 65536:
        raise LinkError(f"connection {text!r}: expected {kind}:HOST:PORT with a port 1-65535")
    if kind == "tcp":
        return TcpTransport(host, port, connect_timeout_s=timeout_s, waiting=waiting)
    if keep_all:
        return UdpTransport(host, port, listen=kind != "udpout", receive_bytes=UDP_RECEIVE_BYTES)
    return opener(host, port)


def _serial_parts(text: str) -> tuple[str, int]:
    body = text.split(":", 1)[1] if text.startswith("serial:") else text
    device, _, baud_text = body.partition(":")
    try:
        return device, int(baud_text) if baud_text else _DEFAULT_BAUD
    except ValueError:
        raise LinkError(f"connection {text!r}: baud rate {baud_text!r} is not a number") from None


_OPENERS: dict[str, Callable[[str, int], Transport]] = {
    "tcp": TcpTransport,
    "udpin": lambda h, p: UdpTransport(h, p, listen=True),
    "udp": lambda h, p: UdpTransport(h, p, listen=True),
    "udpout": lambda h, p: UdpTransport(h, p, listen=False),
}


def _why(exc: OSError) -> str:
    return exc.strerror or str(exc)
