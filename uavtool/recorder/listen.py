"""Listening to a link before and while recording it (``uavtool record``): the tap that
keeps every frame, the vehicles heard on the link (one, or a fleet's), and the wait until
each has spoken, placed itself and told its home."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from uavtool.errors import LinkError
from uavtool.geo import GeoPoint
from uavtool.link import VehicleLink
from uavtool.recorder.config import RecordConfig
from uavtool.recorder.sink import LinkRecorder
from uavtool.recorder.watch import VehicleWatch, frame_ids

LISTEN_S = 1.5
"""With ``direct``: how long to listen for another ground station before speaking."""
_STREAM_REQUEST_S = 2.0


@dataclass(slots=True)
class LinkTap:
    """Every frame crossing the link: held until the file exists, then written; frames from
    systems other than the recorded vehicles also go to their watches."""

    held: list[tuple[str, bytes, int, Any]] = field(default_factory=list)
    recorder: LinkRecorder | None = None
    watches: dict[int, VehicleWatch] = field(default_factory=dict)
    clock: Callable[[], float] = time.monotonic

    def __call__(self, direction: str, frames: list[bytes], decoded: list[Any] | None) -> None:
        now_ns = time.time_ns()
        watches = self.watches
        for i, frame in enumerate(frames):
            msg = None if decoded is None else decoded[i]
            if self.recorder is not None:
                self.recorder.mavlink(direction, frame, msg)
            else:
                self.held.append((direction, frame, now_ns, msg))
            if watches and direction == "in" and frame_ids(frame)[0] not in watches:
                now_s = self.clock()
                for watch in watches.values():
                    watch.foreign(frame, now_s)


class VehicleSource(Protocol):
    """Where the vehicles' messages come from: one vehicle's link, or a fleet's."""

    name: str

    @property
    def links(self) -> list[VehicleLink]:
        """The link of each vehicle heard so far."""
        ...

    def poll(self, timeout_s: float) -> list[tuple[VehicleLink, list[Any]]]: ...

    def heartbeat(self) -> None: ...


class OneLink:
    """The link of one vehicle: the first one heard on it."""

    def __init__(self, link: VehicleLink) -> None:
        self.link = link
        self.name = link.name

    @property
    def links(self) -> list[VehicleLink]:
        return [self.link] if self.link.target_system else []

    def poll(self, timeout_s: float) -> list[tuple[VehicleLink, list[Any]]]:
        msgs = self.link.poll(timeout_s)
        return [(self.link, msgs)] if self.link.target_system else []

    def heartbeat(self) -> None:
        self.link.heartbeat()


def wait_vehicles(
    source: VehicleSource,
    tap: LinkTap,
    config: RecordConfig,
    say: Callable[[str], None],
    stop_now: Callable[[], bool],
) -> dict[int, tuple[GeoPoint, str]]:
    """Listen until ``config.vehicles`` vehicles' heartbeats and positions are known (and
    each one's home, for up to ``home_wait_s`` more); the origin of each vehicle's local
    frame and where it came from, by system id."""
    clock = time.monotonic
    deadline = clock() + config.timeout_s
    found_s: float | None = None
    positioned_s: dict[int, float] = {}
    last_request: float | None = None
    while True:
        now = clock()
        links = source.links
        for link in links:
            if link.target_system not in tap.watches:
                tap.watches[link.target_system] = VehicleWatch(
                    link.target_system, link.target_component, addressed=config.vehicles > 1
                )
                found_s = now if found_s is None else found_s
                say(f"heard vehicle sysid {link.target_system}")
        origins: dict[int, tuple[GeoPoint, str]] = {}
        for link in links:
            state = link.state
            if state.position is None or state.heartbeat is None:
                continue
            since_s = positioned_s.setdefault(link.target_system, now)
            if state.home is not None:
                origins[link.target_system] = state.home, "HOME_POSITION"
            elif now - since_s >= config.home_wait_s:
                p = state.position
                fix = GeoPoint(p.lat / 1e7, p.lon / 1e7, (p.alt - p.relative_alt) / 1000.0)
                origins[link.target_system] = fix, "first fix: no HOME_POSITION heard"
        if len(origins) == config.vehicles:
            # each watch starts from the vehicle's state as last heard: a watch that has not
            # had a heartbeat yet would take an arming that comes before its first one as
            # how the vehicle was, and never say "armed"
            for link in links:
                seen = tap.watches[link.target_system]
                heartbeat = link.state.heartbeat
                if seen.mode_unknown and heartbeat is not None:
                    seen.vehicle(heartbeat, now)
            return origins
        if stop_now():
            raise KeyboardInterrupt  # before anything was recorded: no file
        if now > deadline:
            raise LinkError(_not_heard(source, config, positioned_s))
        quiet = not tap.watches or any(w.gcs_present(now) for w in tap.watches.values())
        # direct: ask for the streams once we have listened long enough to hear a ground station
        listened = found_s is not None and now - found_s >= LISTEN_S
        due = last_request is None or now - last_request >= _STREAM_REQUEST_S
        if config.direct and listened and not quiet and due:
            source.heartbeat()
            for link in links:
                link.request_streams()
            last_request = now
        for link, msgs in source.poll(0.05):
            watch = tap.watches.get(link.target_system)
            if watch is not None:
                for msg in msgs:
                    watch.vehicle(msg, clock())


def _not_heard(source: VehicleSource, config: RecordConfig, positioned_s: dict[int, float]) -> str:
    """Why the recording could not start: what was heard of the vehicles asked for."""
    passive = not config.direct
    heard = sorted(link.target_system for link in source.links)
    if config.vehicles == 1:
        what = "heartbeat" if not heard else "position"
        hint = (
            "; nothing was sent (passive): is the vehicle or its router sending to this "
            "address? --direct asks for its streams"
            if passive
            else ""
        )
        return f"{source.name}: no {what} from a vehicle in {config.timeout_s:g} s{hint}"
    hint = (
        "; nothing was sent (passive): are the vehicles or their router sending to this "
        "address? --direct asks for their streams"
        if passive
        else ""
    )
    if not heard:
        said = "heard no vehicle"
    else:
        noun = "vehicle" if len(heard) == 1 else "vehicles"
        said = f"heard {noun} {', '.join(map(str, heard))}"
    unplaced = [k for k in heard if k not in positioned_s]
    where = f"; no position from {', '.join(map(str, unplaced))}" if unplaced else ""
    return f"{source.name}: {said} of {config.vehicles} in {config.timeout_s:g} s{where}{hint}"
