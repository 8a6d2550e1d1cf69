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
import sys
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from uavtool.errors import LinkError
from uavtool.mavlink.fields import misfit
from uavtool.mavlink.framing import Frame, FrameParser, new_encoder
from uavtool.mavlink.packing import pack

log = logging.getLogger(__name__)

_KINDS = ("tcpin", "udpin", "udpout", "tcp")
_TCP_BACKLOG_LIMIT = 4 << 20  # bytes queued for a slow TCP client before we drop it
MAX_UDP_PEERS = 16
"""Peers one ``udpin`` endpoint serves at once (ArduPilot has a fixed number of MAVLink
channels; routers bound their tables). When more write, :meth:`UdpSocket.expire` decides who
keeps a place: see there."""
UDP_PEER_TIMEOUT_NS = 10_000_000_000
"""A ``udpin`` peer not heard from for this long (real time) is forgotten, as MAVLink routers
expire their UDP routes. Peers are timed in real time whatever the speed-up: a ground station
sends a HEARTBEAT every second of its own clock."""
UDP_PEER_LIVE_NS = 2_000_000_000
"""A peer heard from within this long is live (a ground station's HEARTBEAT comes every
second); a longer gap ends its steady contact."""
UDP_PEER_STEADY_NS = 500_000_000
"""A live peer heard from without a gap for at least this long is in steady contact: it came
back, as a ground station does, where a spoofed or flooding source writes once."""
_RECENT_UDP_PEERS = 4096
"""Peers that lost their place, remembered so that one that comes back (a ground station's
next HEARTBEAT) keeps its steady contact; a flood of new addresses must outpace this."""


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
        self.heard_ns: int | None = None  # real time (monotonic) of the last frame accepted
        self.live_since_ns: int | None = None  # start of its contact without a gap > LIVE
        self.earlier: tuple[int, int] | None = None  # (heard_ns, live_since_ns) before a restart

    def heard(self, now_ns: int) -> None:
        """A frame from the peer was accepted at ``now_ns`` (``time.monotonic_ns``)."""
        last, since = (self.heard_ns, self.live_since_ns) if self.earlier is None else self.earlier
        self.earlier = None
        if last is None or since is None or now_ns - last > UDP_PEER_LIVE_NS:
            since = now_ns
        self.heard_ns, self.live_since_ns = now_ns, since

    def send(self, msg: Any) -> None:
        """Pack ``msg`` with this link's sequence numbers and send it. A message with a value
        its field cannot carry is not sent (logged and counted): one bad value must not take
        the vehicle down."""
        if self.closed:
            return
        try:
            buf = pack(msg, self.encoder)
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
        self.peers_refused = 0  # peers turned away or evicted because MAX_UDP_PEERS wrote
        self._recent: OrderedDict[tuple[str, int], tuple[int, int]] = OrderedDict()
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
            if link is None:  # served for now; expire() decides whether it keeps a place
                link = self._make_link(f"udp:{addr[0]}:{addr[1]}", self._sender(addr))
                link.earlier = self._recent.pop(addr, None)
                self.links[addr] = link
            out.append((link, data))
        return out

    def expire(self, now_ns: int) -> list[Link]:
        """Forget ``udpin`` peers that are closed, sent nothing we accepted, or went silent
        for ``UDP_PEER_TIMEOUT_NS``, then the peers beyond ``MAX_UDP_PEERS``; return their
        links. ``now_ns`` is ``time.monotonic_ns()``. The ``udpout`` peer is configured and
        stays.

        When more than ``MAX_UDP_PEERS`` write, the first to go are the peers not live (least
        recently heard first), then the live ones that wrote once rather than in steady
        contact (least recently heard first), and last the peers in steady contact (the most
        recent contact first). A spoofed source that writes every few seconds, or a flood of
        new addresses, therefore never keeps a ground station out: its first HEARTBEAT takes
        a one-off's place at once, and from its second on it is in steady contact and stays.
        Sixteen sources in steady contact keep their places, as a router keeps live routes.
        """
        if self.endpoint.kind != "udpin":
            return []
        gone = [
            addr
            for addr, link in self.links.items()
            if link.closed or link.heard_ns is None or now_ns - link.heard_ns > UDP_PEER_TIMEOUT_NS
        ]
        out = [self.links.pop(addr) for addr in gone]
        excess = len(self.links) - MAX_UDP_PEERS
        if excess > 0:
            order = sorted(self.links, key=lambda addr: _standing(self.links[addr], now_ns))
            for addr in order[:excess]:
                link = self.links.pop(addr)
                self._remember(addr, link)
                out.append(link)
            self.peers_refused += excess
        return out

    def _remember(self, addr: tuple[str, int], link: Link) -> None:
        if link.heard_ns is None or link.live_since_ns is None:
            return
        self._recent[addr] = (link.heard_ns, link.live_since_ns)
        self._recent.move_to_end(addr)
        while len(self._recent) > _RECENT_UDP_PEERS:
            self._recent.popitem(last=False)


def _standing(link: Link, now_ns: int) -> tuple[int, int]:
    """Order in which ``udpin`` peers lose their place (the smallest first)."""
    heard = link.heard_ns or 0
    since = link.live_since_ns or heard
    if now_ns - heard > UDP_PEER_LIVE_NS:
        return (0, heard)
    if heard - since < UDP_PEER_STEADY_NS:
        return (1, heard)
    return (2, -since)


def _open(endpoint: Endpoint, kind: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, kind)
    if kind == socket.SOCK_STREAM:
        # TCP: only lets us listen again while old connections linger in TIME_WAIT.
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    elif sys.platform == "win32":  # pragma: no cover - Windows only
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_EXCLUSIVEADDRUSE, 1)  # type: ignore[attr-defined]
    # UDP: no SO_REUSEADDR nor SO_REUSEPORT, so no other socket can bind our port and take
    # the datagrams ground stations send us.
    try:
        sock.bind((endpoint.host, endpoint.port))
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            raise LinkError(
                f"{endpoint}: cannot listen: port {endpoint.port} is in use by another program"
                f" (another uavtool sitl?); stop it, or choose another port"
                f" (e.g. {endpoint.kind}:{endpoint.host}:{endpoint.port + 1}, or --instance 1)"
            ) from None
        raise LinkError(f"{endpoint}: cannot listen: {exc.strerror or exc}") from None
    sock.setblocking(False)
    return sock
