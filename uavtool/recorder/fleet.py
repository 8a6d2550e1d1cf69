"""One link that carries a fleet (a radio, a router's UDP port, several vehicles sending to one
address): read once, every frame tapped once, each vehicle's frames handed to a
`~uavtool.link.VehicleLink` of its own, which keeps that vehicle's state as it does on a link
of its own."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from uavtool.link import Transport, VehicleLink
from uavtool.link.client import GCS_COMPID, GCS_SYSID, Tap, is_vehicle_heartbeat
from uavtool.link.transport import UdpTransport
from uavtool.mavlink.framing import Frame, FrameParser, new_encoder


class FleetLink:
    """Reads ``transport`` and sorts what arrives by system id: the first ``count`` vehicles
    heard (a vehicle is heard by its HEARTBEAT, as a `VehicleLink` locks onto one) each get a
    `VehicleLink`; frames of other systems (ground stations, vehicles beyond ``count``) only
    reach ``tap``, as every frame does. ``ignored`` hears each vehicle beyond ``count`` once.

    What a vehicle's link sends goes out on ``transport``, tapped; on a ``udpin`` link, to
    the address that vehicle speaks from (the transport answers whoever spoke last)."""

    def __init__(
        self,
        transport: Transport,
        *,
        tap: Tap,
        count: int,
        ignored: Callable[[int], None] | None = None,
    ) -> None:
        self.transport = transport
        self.name = transport.name
        self.tap = tap
        self.count = count
        self.ignored = ignored
        self.vehicles: dict[int, VehicleLink] = {}
        """Each vehicle's link by system id, in the order they were heard."""
        self._parser = FrameParser()
        self._beyond: set[int] = set()
        self._answers = isinstance(transport, UdpTransport) and transport.name.startswith("udpin")
        self._peers: dict[int, Any] = {}  # sysid -> the address it last spoke from (udpin)
        # one sequence for every frame we send on this link, whichever vehicle it is for
        self._encoder = new_encoder(sysid=GCS_SYSID, compid=GCS_COMPID)

    @property
    def links(self) -> list[VehicleLink]:
        return list(self.vehicles.values())

    def poll(self, timeout_s: float) -> list[tuple[VehicleLink, list[Any]]]:
        """One read: each vehicle's link that got frames in it, with its fresh messages."""
        data = self.transport.recv(timeout_s)
        if not data:
            return []
        frames = self._parser.feed(data)
        if not frames:
            return []
        self.tap("in", [frame.raw for frame in frames], [frame.msg for frame in frames])
        peer = getattr(self.transport, "peer", None) if self._answers else None
        mine: dict[int, list[Frame]] = {}
        for frame in frames:
            sysid = frame.msg.get_srcSystem()
            if sysid not in self.vehicles and not self._new_vehicle(frame.msg):
                continue
            mine.setdefault(sysid, []).append(frame)
            if peer is not None:
                self._peers[sysid] = peer
        return [
            (self.vehicles[sysid], self.vehicles[sysid].take(got)) for sysid, got in mine.items()
        ]

    def heartbeat(self) -> None:
        """Our heartbeat, once to each address the vehicles speak from (once in all on a link
        with one peer: a radio, a router, TCP)."""
        told = set()
        for sysid, link in self.vehicles.items():
            peer = self._peers.get(sysid)
            if peer not in told:
                told.add(peer)
                link.heartbeat()

    def send_for(self, sysid: int, data: bytes) -> None:
        peer = self._peers.get(sysid)
        if peer is not None and isinstance(self.transport, UdpTransport):
            self.transport.send_to(data, peer)
        else:
            self.transport.send(data)

    def _new_vehicle(self, msg: Any) -> bool:
        sysid = msg.get_srcSystem()
        if not is_vehicle_heartbeat(msg):
            return False
        if len(self.vehicles) >= self.count:
            if sysid not in self._beyond:
                self._beyond.add(sysid)
                if self.ignored is not None:
                    self.ignored(sysid)
            return False
        link = VehicleLink(
            _Outbox(self, sysid), tap=self.tap, announce=False, encoder=self._encoder
        )
        self.vehicles[sysid] = link
        return True


class _Outbox:
    """A vehicle's side of a shared link: what its `VehicleLink` sends goes out on the
    fleet's transport; what it receives, the fleet hands it (``VehicleLink.take``)."""

    def __init__(self, fleet: FleetLink, sysid: int) -> None:
        self.fleet = fleet
        self.sysid = sysid
        self.name = fleet.name

    def send(self, data: bytes) -> None:
        self.fleet.send_for(self.sysid, data)

    def recv(self, timeout_s: float) -> bytes:
        del timeout_s
        return b""

    def close(self) -> None:
        """The fleet's transport is closed by its owner."""
