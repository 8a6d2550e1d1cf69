"""A small raw-MAVLink test client over TCP/UDP, built on pymavlink's dialect only."""

from __future__ import annotations

import math
import socket
import time
from collections.abc import Callable
from typing import Any

from uavtool.mavlink import FrameParser, new_encoder
from uavtool.mavlink import mavlink as M


class Client:
    """Talks to the vehicle like a ground station (sysid 255, compid 190)."""

    def __init__(
        self,
        sock: socket.socket,
        *,
        udp_addr: tuple[str, int] | None = None,
        sysid: int = 255,
        compid: int = 190,
        signing_key: bytes | None = None,
    ) -> None:
        self.sock = sock
        self.sock.settimeout(0.05)
        self.udp_addr = udp_addr
        self.parser = FrameParser(signing_key=signing_key)
        self.enc = new_encoder(sysid=sysid, compid=compid, signing_key=signing_key)
        self.received: list[Any] = []  # every message, in order
        self.frames: list[Any] = []
        self.latest: dict[str, Any] = {}
        self._cursor = 0
        self._sent_at = 0  # len(received) when the last command was sent

    @classmethod
    def tcp(cls, port: int, **kw: Any) -> Client:
        sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)  # no Nagle delay on commands
        return cls(sock, **kw)

    def close(self) -> None:
        self.sock.close()

    # ---------------------------------------------------------------- I/O
    def send_raw(self, data: bytes) -> None:
        if self.udp_addr is not None:
            self.sock.sendto(data, self.udp_addr)
        else:
            self.sock.sendall(data)

    def send(self, msg: Any) -> None:
        data = msg.pack(self.enc)
        self.enc.seq = (self.enc.seq + 1) & 0xFF
        self.send_raw(data)

    def pump(self, seconds: float = 0.0) -> list[Any]:
        """Read for ``seconds`` (at least once); return the new messages."""
        new: list[Any] = []
        end = time.monotonic() + seconds
        while True:
            try:
                data = self.sock.recv(65536)
            except (TimeoutError, BlockingIOError):
                data = None
            except ConnectionResetError:
                # The vehicle dropped the link while our last frames were still unread on its
                # side: TCP resets instead of closing. Either way the link is gone.
                return new
            if data:
                for frame in self.parser.feed(data):
                    self.frames.append(frame)
                    self.received.append(frame.msg)
                    self.latest[frame.msg.get_type()] = frame.msg
                    new.append(frame.msg)
            if time.monotonic() >= end:
                return new

    def wait_for(
        self, msg_type: str, cond: Callable[[Any], bool] | None = None, timeout: float = 10.0
    ) -> Any:
        """The next matching message after the last one a wait_for returned (expect-style)."""
        end = time.monotonic() + timeout
        while True:
            while self._cursor < len(self.received):
                msg = self.received[self._cursor]
                self._cursor += 1
                if msg.get_type() == msg_type and (cond is None or cond(msg)):
                    return msg
            if time.monotonic() >= end:
                raise AssertionError(f"no {msg_type} within {timeout} s")
            self.pump(0.02)

    def reason(self, timeout: float = 10.0) -> str:
        """The text of the first STATUSTEXT since the last command was sent: ArduPilot says
        why it refuses a command just before its COMMAND_ACK."""
        end = time.monotonic() + timeout
        while True:
            for msg in self.received[self._sent_at :]:
                if msg.get_type() == "STATUSTEXT":
                    return str(msg.text)
            if time.monotonic() >= end:
                raise AssertionError(f"no STATUSTEXT within {timeout} s")
            self.pump(0.02)

    def wait_until(
        self, cond: Callable[[Client], bool], timeout: float = 30.0, what: str = ""
    ) -> None:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.pump(0.02)
            if cond(self):
                return
        raise AssertionError(f"timed out waiting for {what or cond}")

    # ---------------------------------------------------------------- helpers
    def command(
        self, command: int, *params: float, target: tuple[int, int] = (1, 1), timeout: float = 5.0
    ) -> Any:
        p = [*params, *([0.0] * (7 - len(params)))]
        self._sent_at = len(self.received)
        self.send(M.MAVLink_command_long_message(*target, command, 0, *p))
        return self.wait_for("COMMAND_ACK", lambda m: m.command == command, timeout)

    def command_int(
        self,
        command: int,
        frame: int,
        x: int,
        y: int,
        z: float,
        *params: float,
        timeout: float = 5.0,
    ) -> Any:
        p = [*params, *([0.0] * (4 - len(params)))]
        self._sent_at = len(self.received)
        self.send(M.MAVLink_command_int_message(1, 1, frame, command, 0, 0, *p, x, y, z))
        return self.wait_for("COMMAND_ACK", lambda m: m.command == command, timeout)

    def heartbeat(self) -> None:
        self.send(M.MAVLink_heartbeat_message(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0, 3))

    def set_mode(self, name: str) -> Any:
        from uavtool.mavlink.dialect import COPTER_MODES

        return self.command(M.MAV_CMD_DO_SET_MODE, 1, COPTER_MODES[name])

    def alt_m(self) -> float:
        return float(self.latest["GLOBAL_POSITION_INT"].relative_alt) / 1000.0

    def boot_s(self) -> float:
        return float(self.latest["GLOBAL_POSITION_INT"].time_boot_ms) / 1000.0

    def takeoff(self, alt_m: float = 10.0) -> None:
        assert self.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
        assert self.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        assert (
            self.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt_m).result
            == M.MAV_RESULT_ACCEPTED
        )
        self.wait_until(
            lambda c: "GLOBAL_POSITION_INT" in c.latest and c.alt_m() > alt_m - 0.3,
            what=f"takeoff to {alt_m} m",
        )

    def statustexts(self) -> list[str]:
        return [m.text for m in self.received if m.get_type() == "STATUSTEXT"]
