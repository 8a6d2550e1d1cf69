"""A ground station wired straight into an in-process vehicle: no sockets, no wall clock.

Frames still cross the vehicle's parser, session and encoder; time advances only when the test
says so (``run``), so what these tests see is a function of what they send.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from uavtool.mavlink import FrameParser, new_encoder
from uavtool.mavlink import mavlink as M
from uavtool.mavlink.dialect import COPTER_MODES
from uavtool.sitl import Sitl, SitlConfig
from uavtool.sitl.params import PARAM_SPECS

_NS = 1_000_000_000


class Pilot:
    """Talks to ``sitl`` as sysid 255 / compid 190, stepping the vehicle itself (or, with
    ``step``, stepping whatever else moves its clock: a fleet's world)."""

    def __init__(
        self, sitl: Sitl | None = None, *, step: Callable[[], None] | None = None, **config: Any
    ) -> None:
        self.sitl = sitl if sitl is not None else Sitl(SitlConfig(endpoints=(), **config))
        self._step = step or self.sitl.step
        self.target = self.sitl.sysid
        self._out = bytearray()
        self.link = self.sitl.attach("pilot", self._out.extend)
        self.parser = FrameParser()
        self.enc = new_encoder(sysid=255, compid=190)
        self.received: list[Any] = []
        self.latest: dict[str, Any] = {}

    # ---------------------------------------------------------------- I/O
    def send(self, msg: Any) -> None:
        self.send_raw(msg.pack(self.enc))
        self.enc.seq = (self.enc.seq + 1) & 0xFF

    def send_raw(self, data: bytes) -> None:
        self.sitl.deliver(self.link, data)
        self._collect()

    def run(self, seconds: float) -> None:
        end = self.sitl.now_ns + round(seconds * _NS)
        while self.sitl.now_ns < end:
            self._step()
            self._collect()
        self._collect()  # what it was sent while another stepped the clock

    def run_until(self, cond: Callable[[Pilot], bool], seconds: float, what: str) -> None:
        end = self.sitl.now_ns + round(seconds * _NS)
        while not cond(self):
            if self.sitl.now_ns >= end:
                raise AssertionError(f"no {what} within {seconds} s of vehicle time")
            self._step()
            self._collect()

    def _collect(self) -> None:
        if not self._out:
            return
        for frame in self.parser.feed(bytes(self._out)):
            self.received.append(frame.msg)
            self.latest[frame.msg.get_type()] = frame.msg
        self._out.clear()

    def of_type(self, name: str) -> list[Any]:
        return [m for m in self.received if m.get_type() == name]

    def statustexts(self) -> list[str]:
        return [m.text for m in self.of_type("STATUSTEXT")]

    # ---------------------------------------------------------------- helpers
    def command(self, command: int, *params: float) -> Any:
        p = [*params, *([0.0] * (7 - len(params)))]
        before = len(self.received)
        self.send(M.MAVLink_command_long_message(self.target, 1, command, 0, *p))
        acks = [
            m
            for m in self.received[before:]
            if m.get_type() == "COMMAND_ACK" and m.command == command
        ]
        assert len(acks) == 1, f"{len(acks)} COMMAND_ACKs for command {command}"
        return acks[0]

    def set_mode(self, name: str) -> Any:
        return self.command(M.MAV_CMD_DO_SET_MODE, 1, COPTER_MODES[name])

    def set_param(self, name: str, value: float) -> Any:
        before = len(self.received)
        self.send(M.MAVLink_param_set_message(self.target, 1, name.encode(), value, 9))
        echoes = [
            m
            for m in self.received[before:]
            if m.get_type() == "PARAM_VALUE" and m.param_id == name
        ]
        assert len(echoes) == 1, f"{len(echoes)} PARAM_VALUE answers for {name}"
        return echoes[0]

    @property
    def armed(self) -> bool:
        hb = self.latest.get("HEARTBEAT")
        return hb is not None and bool(hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)

    def alt_m(self) -> float:
        return float(self.latest["GLOBAL_POSITION_INT"].relative_alt) / 1000.0

    def mode(self) -> int:
        return int(self.latest["HEARTBEAT"].custom_mode)

    def takeoff(self, alt_m: float) -> None:
        self.run(0.2)  # telemetry to judge by
        assert self.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
        assert self.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
        ack = self.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt_m)
        assert ack.result == M.MAV_RESULT_ACCEPTED, self.statustexts()[-3:]
        self.run_until(lambda p: p.alt_m() > alt_m - 0.3, 60, f"takeoff to {alt_m} m")

    def land(self) -> None:
        assert self.command(M.MAV_CMD_NAV_LAND).result == M.MAV_RESULT_ACCEPTED
        self.run_until(lambda p: not p.armed, 120, "landing")
        assert abs(self.alt_m()) < 0.05

    def recover(self) -> None:
        """What an operator does after a session of nonsense: parameters back to their
        defaults, and the vehicle landed and disarmed."""
        for spec in PARAM_SPECS:
            if spec.name not in ("SYSID_THISMAV", "SIM_SPEEDUP"):
                self.set_param(spec.name, spec.default)
        for msg_id in (M.MAVLINK_MSG_ID_HEARTBEAT, M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT):
            self.command(M.MAV_CMD_SET_MESSAGE_INTERVAL, msg_id, 0)  # its default rate
        self.run(0.5)
        if self.armed:
            self.set_mode("LAND")
            self.run_until(lambda p: not p.armed, 240, "landing to recover")

    def normal_flight(self, alt_m: float = 5.0) -> None:
        self.takeoff(alt_m)
        self.land()
