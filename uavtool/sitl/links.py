"""MAVLink transports for the vehicle: ``tcpin:``, ``udpin:``, ``udpout:`` and ``tcp:`` endpoints.

All sockets are non-blocking and served from the simulation thread with ``selectors``.
Each connected peer is a :class:`Link` with its own parser, encoder (sequence numbers) and
stream rates, as each ArduPilot serial port is a channel of its own.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import socket
import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from uavtool.errors import LinkError
from uavtool.mavlink.fields import misfit
from uavtool.mavlink.framing import Frame, FrameParser, new_encoder

log = logging.getLogger(__name__)

_KINDS = ("tcpin", "udpin", "udpout", "tcp")
_TCP_BACKLOG_LIMIT = 4 << 20  # bytes queued for a slow TCP client before we drop it
MAX_UDP_PEERS = 16
"""Peers one ``udpin`` endpoint serves at once; datagrams from more are dropped until one
expires (ArduPilot has a fixed number of MAVLink channels; routers bound their tables)."""
UDP_PEER_TIMEOUT_NS = 10_000_000_000
"""A ``udpin`` peer heard from for this long (vehicle time) is forgotten, as MAVLink routers
expire their UDP routes; ground stations send a HEARTBEAT every second."""


@dataclass(frozen=True, slots=True)
class Endpoint:
    """A parsed endpoint string such as ``tcpin:127.0.0.1:5760``."""

    kind: str
    host: str
    port: int

    def __str__(self) -> str:
        return f"{self.kind}:{self.host}:{self.port}"

    def offset(self, instance: int) -> Endpoint:
        """The endpoint of vehicle ``instance`` (ports +10 per instance, as ArduPilot's SITL)."""
        if instance == 0 or self.port == 0:
            return self
        return Endpoint(self.kind, self.host, self.port + 10 * instance)


def parse_endpoint(text: str) -> Endpoint:
    """Parse ``KIND:HOST:PORT`` (pymavlink style); raises LinkError with what is wrong."""
    parts = text.strip().split(":")
    if len(parts) != 3 or parts[0] not in _KINDS:
        raise LinkError(
            f"endpoint {text!r}: expected KIND:HOST:PORT with KIND one of {', '.join(_KINDS)}"
        )
    kind, host, port_text = parts
    try:
        port = int(port_text)
    except ValueError:
        raise LinkError(f"endpoint {text!r}: port {port_text!r} is not a number") from None
    if not 0 <= port <= 65535:
        raise LinkError(f"endpoint {text!r}: port {port} out of range 0-65535")
    if not host:
        raise LinkError(f"endpoint {text!r}: missing host")
    return Endpoint(kind, host, port)


FrameTap = Callable[[str, "Link", bytes], None]  # (direction "in"/"out", link, frame bytes)


class Link:
    """One MAVLink peer: parses what it sends us and packs what we send it.

    Frames are parsed without the signing key: the vehicle's
    :class:`~uavtool.sitl.signing.SigningStreams` judges signatures for all its links at once.
    """

    def __init__(
        self,
        name: str,
        send_bytes: Callable[[bytes], None],
        *,
        sysid: int,
        compid: int,
        signing_key: bytes | None,
        link_id: int,
        tap: FrameTap | None,
    ) -> None:
        self.name = name
        self._send_bytes = send_bytes
        self.parser = FrameParser()
        self.encoder = new_encoder(
            sysid=sysid, compid=compid, signing_key=signing_key, link_id=link_id
        )
        self.tap = tap
        self.closed = False
        self.session: Any = None  # the GcsSession serving this link
        self.frames_sent = 0
        self.unsendable = 0  # messages refused because a value did not fit its field
        self.faults = 0  # unexpected errors while serving this peer
        self.heard_ns: int | None = None  # vehicle time of the last frame accepted from it

    def send(self, msg: Any) -> None:
        """Pack ``msg`` with this link's sequence numbers and send it. A message with a value
        its field cannot carry is not sent (logged and counted): one bad value must not take
        the vehicle down."""
        if self.closed:
            return
        try:
            buf = msg.pack(self.encoder)
        except (struct.error, OverflowError, ValueError, TypeError) as exc:
            self.unsendable += 1
            log.error("%s: %s not sent: %s", self.name, msg.get_type(), misfit(msg) or exc)
            return
        self.encoder.seq = (self.encoder.seq + 1) & 0xFF
        self.frames_sent += 1
        if self.tap is not None:
            self.tap("out", self, buf)
        self._send_bytes(buf)

    def receive(self, data: bytes) -> list[Frame]:
        frames = self.parser.feed(data)
        if self.tap is not None:
            for frame in frames:
                self.tap("in", self, frame.raw)
        return frames


class _Socketed:
    """Base for objects that own a socket registered with the server's selector."""

    sock: socket.socket

    def on_readable(self) -> list[tuple[Link, bytes]]:
        raise NotImplementedError

    def on_writable(self) -> None:
        """Flush queued output (TCP only)."""

    def wants_write(self) -> bool:
        return False

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self.sock.close()


LinkFactory = Callable[[str, Callable[[bytes], None]], Link]


class TcpConnection(_Socketed):
    def __init__(self, sock: socket.socket, make_link: LinkFactory, name: str) -> None:
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock = sock
        self._out = bytearray()
        self.link = make_link(name, self._send)

    def _send(self, data: bytes) -> None:
        if self.link.closed:
            return
        if not self._out:
            try:
                sent = self.sock.send(data)
            except BlockingIOError:
                sent = 0
            except OSError:
                self.link.closed = True
                return
            data = data[sent:]
        if data:
            self._out += data
            if len(self._out) > _TCP_BACKLOG_LIMIT:
                self.link.closed = True

    def wants_write(self) -> bool:
        return bool(self._out)

    def on_writable(self) -> None:
        try:
            sent = self.sock.send(self._out)
        except BlockingIOError:
            return
        except OSError:
            self.link.closed = True
            return
        del self._out[:sent]

    def on_readable(self) -> list[tuple[Link, bytes]]:
        try:
            data = self.sock.recv(65536)
        except BlockingIOError:
            return []
        except OSError:
            data = b""
        if not data:
            self.link.closed = True
            return []
        return [(self.link, data)]


class TcpListener(_Socketed):
    def __init__(self, endpoint: Endpoint, make_link: LinkFactory) -> None:
        self.endpoint = endpoint
        self._make_link = make_link
        self.sock = _open(endpoint, socket.SOCK_STREAM)
        self.sock.listen(8)
        self.accepted: list[TcpConnection] = []

    @property
    def port(self) -> int:
        return int(self.sock.getsockname()[1])

    def on_readable(self) -> list[tuple[Link, bytes]]:
        try:
            conn, addr = self.sock.accept()
        except BlockingIOError:
            return []
        self.accepted.append(TcpConnection(conn, self._make_link, f"tcp:{addr[0]}:{addr[1]}"))
        return []


class TcpClient(TcpConnection):
    def __init__(self, endpoint: Endpoint, make_link: LinkFactory) -> None:
        try:
            sock = socket.create_connection((endpoint.host, endpoint.port), timeout=5.0)
        except OSError as exc:
            raise LinkError(f"{endpoint}: cannot connect: {exc.strerror or exc}") from None
        self.endpoint = endpoint
        super().__init__(sock, make_link, str(endpoint))


class UdpSocket(_Socketed):
    """``udpin`` (bind, reply to whoever writes) or ``udpout`` (send to a fixed address)."""

    def __init__(self, endpoint: Endpoint, make_link: LinkFactory) -> None:
        self.endpoint = endpoint
        self._make_link = make_link
        self.links: dict[tuple[str, int], Link] = {}
        self.peers_refused = 0  # datagrams dropped because MAX_UDP_PEERS were being served
        if endpoint.kind == "udpin":
            self.sock = _open(endpoint, socket.SOCK_DGRAM)
        else:
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self.sock.setblocking(False)
            addr = (endpoint.host, endpoint.port)
            self.links[addr] = make_link(str(endpoint), self._sender(addr))

    @property
    def port(self) -> int:
        return int(self.sock.getsockname()[1])

    def _sender(self, addr: tuple[str, int]) -> Callable[[bytes], None]:
        def send(data: bytes) -> None:
            try:
                self.sock.sendto(data, addr)
            except OSError as exc:  # nobody listening yet, or a full buffer: UDP drops
                if exc.errno not in (
                    errno.ECONNREFUSED,
                    errno.EAGAIN,
                    errno.ENOBUFS,
                    errno.EWOULDBLOCK,
                ):
                    raise

        return send

    def on_readable(self) -> list[tuple[Link, bytes]]:
        out: list[tuple[Link, bytes]] = []
        for _ in range(64):
            try:
                data, addr = self.sock.recvfrom(65536)
            except (BlockingIOError, ConnectionRefusedError):
                break
            except OSError:
                break
            if self.endpoint.kind == "udpout":
                addr = (self.endpoint.host, self.endpoint.port)
            link = self.links.get(addr)
            if link is None:
                if len(self.links) >= MAX_UDP_PEERS:
                    self.peers_refused += 1
                    continue
                link = self._make_link(f"udp:{addr[0]}:{addr[1]}", self._sender(addr))
                self.links[addr] = link
            out.append((link, data))
        return out

    def expire(self, now_ns: int) -> list[Link]:
        """Forget ``udpin`` peers that are closed, sent nothing we accepted, or went silent
        for ``UDP_PEER_TIMEOUT_NS``; return their links. The ``udpout`` peer is configured
        and stays."""
        if self.endpoint.kind != "udpin":
            return []
        gone = [
            addr
            for addr, link in self.links.items()
            if link.closed or link.heard_ns is None or now_ns - link.heard_ns > UDP_PEER_TIMEOUT_NS
        ]
        return [self.links.pop(addr) for addr in gone]


def _open(endpoint: Endpoint, kind: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, kind)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((endpoint.host, endpoint.port))
    except OSError as exc:
        sock.close()
        raise LinkError(f"{endpoint}: cannot listen: {exc.strerror or exc}") from None
    sock.setblocking(False)
    return sock
