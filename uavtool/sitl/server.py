"""The simulation loop: sim clock, physics steps, links, and pacing against wall time.

One thread owns everything (sockets, autopilot, telemetry), so there are no locks on the
hot path. Simulation time advances in fixed steps (``SIM_RATE_HZ``); wall time only
decides *when* a step runs (``speedup``), never what it computes, so a flight is the same
at ``--speedup 1`` and ``--speedup 50`` for the same commands at the same sim times.
"""

from __future__ import annotations

import logging
import selectors
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from uavtool.mavlink.dialect import mavlink as M
from uavtool.sitl.autopilot import Autopilot
from uavtool.sitl.config import SitlConfig
from uavtool.sitl.gcs import GcsSession
from uavtool.sitl.links import (
    FrameTap,
    Link,
    TcpClient,
    TcpConnection,
    TcpListener,
    UdpSocket,
    _Socketed,
    parse_endpoint,
)
from uavtool.sitl.params import ParamStore
from uavtool.sitl.signing import SigningStreams
from uavtool.sitl.telemetry import Telemetry

log = logging.getLogger(__name__)
_NS = 1_000_000_000
_MAX_LAG_S = 0.25  # at real-time-ish speed-ups, drop lag beyond this instead of bursting
MAX_LINK_FAULTS = 10
"""Unexpected errors serving one peer before its link is dropped (each is logged and counted;
the request that raised it is refused)."""


def serve_paced(
    *,
    step: Callable[[], None],
    poll: Callable[[float], None],
    now_ns: Callable[[], int],
    speedup: Callable[[], float],
    vehicles: Sequence[Sitl],
    stop: threading.Event,
    end_ns: int | None,
) -> None:
    """Step and serve on the wall clock at ``speedup()`` times real time until ``stop`` (or
    sim time ``end_ns``): one vehicle's loop, or a fleet's (its ``vehicles`` all stepped by
    ``step``). Wall time only decides when a step runs. A vehicle's ``pacing_reset`` (its
    SIM_SPEEDUP changed) restarts the pacing; so does falling behind by more than
    ``_MAX_LAG_S`` below 100x, rather than bursting to catch up."""
    wall0 = sim0 = 0.0
    starved = False
    while not stop.is_set() and (end_ns is None or now_ns() < end_ns):
        if starved or any(v.pacing_reset for v in vehicles):
            for v in vehicles:
                v.pacing_reset = False
            wall0, sim0, starved = time.perf_counter(), now_ns() / _NS, False
        step()
        rate = speedup()
        due = wall0 + (now_ns() / _NS - sim0) / rate
        wait = due - time.perf_counter()
        if wait < -_MAX_LAG_S and rate < 100:
            starved = True  # we were starved; don't burst to catch up
        poll(wait)
        # Serve what arrives until the next step is due: incoming traffic must not make sim
        # time run ahead of the speed-up (a ground station's stream did, a flood 5x).
        while (
            not (starved or any(v.pacing_reset for v in vehicles))
            and (wait := due - time.perf_counter()) > 0
        ):
            if stop.is_set():
                return
            poll(wait)


class Sitl:
    """A simulated ArduCopter with its MAVLink endpoints.

    Use as a context manager to run it in a background thread::

        with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20)) as sitl:
            port = sitl.ports[0]
    """

    def __init__(self, config: SitlConfig, *, frame_tap: FrameTap | None = None) -> None:
        self.config = config
        self.sysid = config.sysid + config.instance
        self.compid = config.compid
        self.signing_key = config.signing_key
        self.frame_tap = frame_tap
        params = ParamStore()
        params.set("SYSID_THISMAV", self.sysid)
        params.set("SIM_SPEEDUP", config.speedup)
        params.set("SIM_WIND_SPD", config.wind_speed_ms)
        params.set("SIM_WIND_DIR", config.wind_dir_deg % 360.0)
        for name, value in config.params:
            params.set(name, value)
        self.speedup = params["SIM_SPEEDUP"]
        self.dt_ns = _NS // max(int(params["SIM_RATE_HZ"]), 1)
        self.autopilot = Autopilot(
            home=config.home,
            home_heading_deg=config.home_heading_deg,
            params=params,
            seed=config.seed,
            obstacles=config.obstacles,
            body_radius_m=config.body_radius_m,
            arming_settle_s=config.arming_settle_s,
            mount_roll_trim_deg=config.mount_roll_trim_deg,
        )
        self.telemetry = Telemetry(
            self.autopilot,
            sysid=self.sysid,
            instance=config.instance,
            start_unix_us=(
                int(time.time() * 1e6) if config.start_unix_us is None else config.start_unix_us
            ),
        )
        self.signing = (
            None
            if config.signing_key is None
            else SigningStreams(config.signing_key, unix_us=lambda: time.time_ns() // 1000)
        )
        self.sessions: list[GcsSession] = []
        self.faults = 0  # unexpected errors while serving peers, all links together
        self._selector = selectors.DefaultSelector()
        self._sockets: list[_Socketed] = []
        self._link_counter = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.pacing_reset = True
        self.steps = 0
        self._outages_ns = [(int(a * _NS), int((a + d) * _NS)) for a, d in config.link_outages_s]
        self.link_down = False
        self.rx_bytes = 0  # bytes received on all links, garbage included
        self.error: BaseException | None = None
        try:
            for text in config.endpoints:
                self._open(parse_endpoint(text).offset(config.instance))
        except Exception:
            self.close()
            raise

    # ------------------------------------------------------------------ endpoints
    def _make_link(self, name: str, send: Callable[[bytes], None]) -> Link:
        self._link_counter += 1
        link = Link(
            name,
            send,
            sysid=self.sysid,
            compid=self.compid,
            signing_key=self.signing_key,
            link_id=self._link_counter & 0xFF,
            tap=self.frame_tap,
        )
        session = GcsSession(self, link)
        link.session = session
        self.sessions.append(session)
        return link

    def _open(self, endpoint: Any) -> None:
        sock: _Socketed
        if endpoint.kind == "tcpin":
            sock = TcpListener(endpoint, self._make_link)
        elif endpoint.kind == "tcp":
            sock = TcpClient(endpoint, self._make_link)
        else:
            sock = UdpSocket(endpoint, self._make_link)
        self._register(sock)

    def _register(self, sock: _Socketed) -> None:
        self._sockets.append(sock)
        self._selector.register(sock.sock, selectors.EVENT_READ, sock)

    @property
    def ports(self) -> list[int]:
        """The local port of each endpoint, in order (resolves ``:0`` ephemeral ports)."""
        return [
            int(s.sock.getsockname()[1])
            for s in self._sockets
            if isinstance(s, (TcpListener, UdpSocket))
        ]

    def describe_endpoints(self) -> list[str]:
        out = []
        for s in self._sockets:
            ep = getattr(s, "endpoint", None)
            if ep is None:
                continue
            port = s.sock.getsockname()[1] if ep.kind in ("tcpin", "udpin") else ep.port
            out.append(f"{ep.kind}:{ep.host}:{port}")
        return out

    def attach(self, name: str, send: Callable[[bytes], None]) -> Link:
        """A link to a peer that is not a socket: the vehicle hands its bytes to ``send``, and
        the peer's bytes come in through :meth:`deliver` (the lockstep transport uses this)."""
        return self._make_link(name, send)

    def deliver(self, link: Link, data: bytes) -> None:
        """Bytes that arrived from ``link``'s peer: parse them and act on every whole frame
        (lost, as on a radio, while a fault-injected outage lasts)."""
        self.rx_bytes += len(data)
        if self.link_down:
            return
        for frame in link.receive(data):
            if link.closed:
                return
            try:
                link.session.handle(frame)
            except Exception:  # a bug must not let one peer take the vehicle down
                self.fault(link, frame.msg.get_type())

    def fault(self, link: Link, what: str) -> None:
        """Log and count the exception being handled while serving ``link``'s peer (for
        ``what``); drop the link after ``MAX_LINK_FAULTS``. The vehicle and its other links
        go on."""
        self.faults += 1
        link.faults += 1
        log.exception("fault %d on %s while handling %s", link.faults, link.name, what)
        if link.faults >= MAX_LINK_FAULTS and not link.closed:
            log.error("%s: dropped after %d faults", link.name, link.faults)
            link.closed = True

    # ------------------------------------------------------------------ parameters
    def set_param(self, name: str, value: float) -> float:
        stored = self.autopilot.params.set(name, value)
        if name == "SIM_SPEEDUP" and stored > 0:
            self.speedup = stored
            self.pacing_reset = True
        self.autopilot.apply_params()
        return stored

    # ------------------------------------------------------------------ running
    @property
    def now_ns(self) -> int:
        return self.autopilot.now_ns

    @property
    def crashed(self) -> bool:
        """True once the vehicle has hit an obstacle or the ground hard (until it restarts)."""
        return self.autopilot.collisions.crashed

    @property
    def crash_reason(self) -> str:
        """The crash's STATUSTEXT, e.g. ``Crash: collision with building 'red'``; "" if none."""
        return self.autopilot.collisions.crash_reason

    @property
    def closest_clearance_m(self) -> float:
        """Least gap (m) between the body sphere and any obstacle while airborne so far (≤ 0
        after a collision, inf without obstacles); see ``sitl.crash.Collisions``."""
        return self.autopilot.collisions.closest_clearance_m

    @property
    def closest_obstacle(self) -> str:
        """Name of the obstacle ``closest_clearance_m`` was measured to ("" if none)."""
        return self.autopilot.collisions.closest_obstacle

    def broadcast(self, msg: Any) -> None:
        for session in self.sessions:
            session.send(msg)

    def step(self) -> None:
        """Advance the simulation by one physics step and send what is due."""
        self.advance()
        self.publish()

    def advance(self) -> None:
        """The first half of :meth:`step`: one physics step, nothing sent yet (a fleet steps
        every vehicle, then judges contacts between them, then lets each speak)."""
        ap = self.autopilot
        now = ap.now_ns + self.dt_ns
        ap.tick(now, self.dt_ns / _NS)
        self.steps += 1
        self.link_down = bool(self._outages_ns) and any(a <= now < b for a, b in self._outages_ns)

    def publish(self) -> None:
        """The second half of :meth:`step`: send what is due at the vehicle's time."""
        ap = self.autopilot
        now = ap.now_ns
        if self.link_down:
            ap.events.clear()  # what the vehicle says during an outage is lost
            return
        while ap.events:
            severity, text = ap.events.popleft()
            self.broadcast(M.MAVLink_statustext_message(severity, text.encode()))
        mission = ap.mission
        if mission.changed:
            mission.changed = False
            self.broadcast(self.telemetry.mission_current())
        while mission.reached:
            self.broadcast(M.MAVLink_mission_item_reached_message(mission.reached.pop(0)))
        if ap.shutter.pending:
            for msg in ap.shutter.feedback(self.telemetry, target_system=0):
                self.broadcast(msg)
        for session in self.sessions:
            try:
                session.tick(now)
            except Exception:  # its telemetry cannot be built or sent: drop that link only
                self.fault(session.link, "telemetry")
                session.link.closed = True

    def poll(self, timeout_s: float) -> None:
        """Serve sockets for up to ``timeout_s`` (0: only what is already waiting)."""
        for conn in self._tcp_connections():
            if conn.wants_write():
                conn.on_writable()
        for key, _ in self._selector.select(max(timeout_s, 0.0)):
            owner: _Socketed = key.data
            for link, data in owner.on_readable():
                self.deliver(link, data)
            if isinstance(owner, TcpListener):
                while owner.accepted:
                    self._register(owner.accepted.pop())
        self._reap()

    def fileno(self) -> int | None:
        """A descriptor that turns readable when any of the vehicle's sockets has something
        to read (its epoll or kqueue), for a loop that serves several vehicles; None where
        the platform's selector has none."""
        fileno = getattr(self._selector, "fileno", None)
        return None if fileno is None else int(fileno())

    def _tcp_connections(self) -> list[TcpConnection]:
        return [s for s in self._sockets if isinstance(s, TcpConnection)]

    def _reap(self) -> None:
        """Close dropped TCP connections and forget expired UDP peers, with their sessions."""
        for sock in list(self._sockets):
            if isinstance(sock, TcpConnection) and sock.link.closed:
                self._selector.unregister(sock.sock)
                sock.close()
                self._sockets.remove(sock)
                self._forget(sock.link)
            elif isinstance(sock, UdpSocket):
                for link in sock.expire(time.monotonic_ns()):
                    link.closed = True
                    self._forget(link)

    def _forget(self, link: Link) -> None:
        if link.session in self.sessions:
            self.sessions.remove(link.session)

    def run(self, *, duration_s: float | None = None) -> None:
        """Run in this thread until ``stop()`` (or for ``duration_s`` of sim time)."""
        end_ns = None if duration_s is None else self.now_ns + int(duration_s * _NS)
        serve_paced(
            step=self.step,
            poll=self.poll,
            now_ns=lambda: self.now_ns,
            speedup=lambda: self.speedup,
            vehicles=(self,),
            stop=self._stop,
            end_ns=end_ns,
        )

    def start(self) -> Sitl:
        """Run in a daemon thread; returns self."""
        self._thread = threading.Thread(
            target=self._run_guarded, name=f"sitl-{self.sysid}", daemon=True
        )
        self._thread.start()
        return self

    def _run_guarded(self) -> None:
        try:
            self.run()
        except BaseException as exc:
            self.error = exc
            log.exception("SITL vehicle stopped")

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
        self.close()

    def close(self) -> None:
        for sock in self._sockets:
            sock.close()
        self._sockets.clear()
        self._selector.close()

    def __enter__(self) -> Sitl:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
