"""One vehicle of a recording (``uavtool record``): its link's state and watch, where its
messages are written, its camera, and what the recording loop knows of it."""

from __future__ import annotations

import time
from typing import Any

from uavtool.autopilot import for_vehicle
from uavtool.geo import enu_from_geo
from uavtool.link import VehicleLink
from uavtool.recorder.config import RecordConfig, Stop, VehicleSummary
from uavtool.recorder.frames import FrameTaker, PoseTrack
from uavtool.recorder.sink import PassiveRecorder
from uavtool.recorder.watch import Event, VehicleWatch
from uavtool.recording import LogLevel
from uavtool.runner.vehicle import telemetry

SILENCE_S = 3.0
"""A link silent this long gets an event (and another when it speaks again)."""


class RecordedVehicle:
    """One recorded vehicle: its link's state, its watch, where its messages are written,
    its camera, and what the loop knows of it (when it last spoke, whether it flew)."""

    def __init__(
        self,
        config: RecordConfig,
        link: VehicleLink,
        watch: VehicleWatch,
        recorder: PassiveRecorder,
        taker: FrameTaker | None,
        *,
        one: bool,
    ) -> None:
        self.config = config
        self.sysid = link.target_system
        self.link = link
        self.watch = watch
        self.recorder = recorder
        self.taker = taker
        self.origin = recorder.origin
        self.one = one
        self.name = "the vehicle" if one else f"vehicle {self.sysid}"
        self.track = PoseTrack()
        self._vehicle_home = link.state.home
        self.last_rx_s = time.monotonic()
        self.silent = False
        self.lost = False
        self.over = False
        """The flight is over: the vehicle flew, and its latest telemetry is landed and
        disarmed."""
        self.armed = False
        self.requested = False

    def heard(self, msgs: list[Any], now: float) -> None:
        """Record what one read brought from the vehicle (maybe nothing)."""
        if msgs:
            if self.silent:
                self.note(LogLevel.INFO, "link: the vehicle speaks again")
            self.last_rx_s, self.silent, self.lost = now, False, False
        elif not self.silent and now - self.last_rx_s >= SILENCE_S:
            self.silent = True
            self.note(LogLevel.WARNING, f"link: nothing heard for {SILENCE_S:g} s")
        said = [over for msg in msgs if (over := self._message(msg, now)) is not None]
        if said:
            self.over = any(said)

    def _message(self, msg: object, now: float) -> bool | None:
        """Record what ``msg`` tells; for a telemetry sample, whether the flight is over."""
        self.watch.vehicle(msg, now)
        kind = msg.get_type()  # type: ignore[attr-defined]
        state = self.link.state
        if kind == "HOME_POSITION" and state.home != self._vehicle_home:
            self._vehicle_home = state.home
            if state.home is not None:
                e, n, u = enu_from_geo(self.origin, state.home)
                self.note(LogLevel.INFO, f"vehicle home now at {e:.1f} E {n:.1f} N {u:.1f} U m")
        if kind != "GLOBAL_POSITION_INT":
            return None
        # Poses stay in one frame for the whole file, whatever the vehicle's home does.
        state.home = self.origin
        autopilot = self.watch.autopilot or for_vehicle(state.heartbeat)
        t = telemetry(self.link, (self.config.gimbal_pitch_deg, 0.0), autopilot)
        state.home = self._vehicle_home
        if t is None:
            return None
        self.track.add(t, now)
        self.recorder.telemetry(t)
        self.armed = t.armed
        return self.watch.flight_over(armed=t.armed, landed=t.landed)

    def tell(self, now: float) -> None:
        """The watch's events, and the camera's frames due now."""
        for event in self.watch.take_events():
            self.recorder.event(event)
        triggers = self.watch.take_triggers()
        if self.taker is None:
            for trigger in triggers:
                self.note(LogLevel.INFO, f"photo trigger ({trigger}): no camera", "camera")
            return
        for f in self.taker.tick(now, self.track, triggers):
            self.recorder.frame(f)
        for event in self.taker.events:
            self.recorder.event(event)
        self.taker.events.clear()

    def finish(self) -> None:
        for f in self.taker.finish(self.track) if self.taker is not None else []:
            self.recorder.frame(f)

    def gaps(self, stop: Stop, start_s: float, end_s: float, *, lost_s: float) -> list[str]:
        """What the recording lacks of this vehicle of what was asked for, one line each (the
        vehicle silent for ``lost_s`` or more before a --duration or --until-landed end, a
        camera that stalled or failed); nothing for Ctrl-C, which ends it where the user
        wanted."""
        if stop is Stop.INTERRUPTED:
            return []
        found = []
        silent_s = end_s - self.last_rx_s
        if silent_s >= lost_s:
            found.append(
                f"link: nothing heard from {self.name} for the last {silent_s:.1f} s "
                f"(since {self.last_rx_s - start_s:.1f} s in)"
            )
        if self.taker is not None:
            camera = self.taker.gap(start_s=start_s, end_s=end_s)
            if camera is not None:
                found.append(camera if self.one else f"{self.name}'s {camera}")
        return found

    def summary(self, gaps: list[str]) -> VehicleSummary:
        c = self.recorder.counts
        return VehicleSummary(
            self.sysid, c["telemetry"], c["frames"], c["photos"], c["events"], tuple(gaps)
        )

    def note(self, level: LogLevel, text: str, source: str = "recorder") -> None:
        self.recorder.event(Event(level, text, source))
