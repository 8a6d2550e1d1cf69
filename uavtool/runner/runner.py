"""The imperative shell around the mission: reads the link, turns what the vehicle says into
observations, feeds them to the mission one at a time, executes its commands, takes its
photos, and records every input and output.

It waits on telemetry, never on fixed sleeps. Its clocks are the link's (``VehicleLink.clock``:
the wall clock for a real vehicle, the vehicle's own clock in lockstep) for silence and its own
heartbeat, and vehicle time for command acknowledgements.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from uavtool.autopilot import COMMAND_NAMES, RESULT_NAMES, Autopilot, for_vehicle
from uavtool.camera import CameraPose
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.images import png_encode
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission import (
    Command,
    CommandResult,
    Event,
    FlightMission,
    GoTo,
    Level,
    LinkLost,
    LinkRestored,
    Observation,
    Outcome,
    Output,
    Photo,
    Result,
    SetGimbal,
    TakePhoto,
    Telemetry,
)
from uavtool.plugins import guarded
from uavtool.runner.camera import CameraSource
from uavtool.runner.live import LiveView
from uavtool.runner.record import MissionRecorder
from uavtool.runner.vehicle import photo_pose, telemetry

Progress = Callable[[str, Telemetry | None], None]
"""Told each mission event, with the latest telemetry."""
VehicleSays = Callable[[str], None]
"""Told what the vehicle says as it arrives: each STATUSTEXT of severity WARNING or worse,
and each refused command with the vehicle's reason."""


@dataclass(frozen=True, slots=True)
class RunnerConfig:
    """Timeouts: ``ack_timeout_s`` in vehicle time, the others on the link's clock."""

    ack_timeout_s: float = 3.0
    link_timeout_s: float = 3.0
    link_report_s: float = 1.0
    heartbeat_s: float = 1.0
    poll_s: float = 0.02
    command_resend_s: float | None = None
    """Send a command again (same command, as MAVSDK and QGroundControl do) when its
    COMMAND_ACK has not come this long (vehicle time) after it was last sent, until
    ``ack_timeout_s`` is up: on a lossy link either may be lost. None: never (lockstep)."""
    target_resend_s: float | None = None
    """Send the current position target again this often while it is the latest command: a
    position target has no ACK, so one lost on a lossy link would cost the move its timeout
    (ArduPilot takes the same target again as no change). None: never — a lockstep link
    loses nothing, and its recordings stay as they were."""


class Runner:
    """Flies ``mission`` on ``link`` with ``camera``; ``scene_origin`` is the geographic
    origin of the camera's world (the scene's home) when it is simulated. ``true_pose``, for
    a simulated vehicle, says where its camera really is (ENU around its home): photos are
    rendered there, while the mission is told the pose the telemetry reports."""

    def __init__(
        self,
        link: VehicleLink,
        camera: CameraSource,
        mission: FlightMission,
        *,
        recorder: MissionRecorder | None,
        live: LiveView | None = None,
        scene_origin: GeoPoint | None = None,
        true_pose: Callable[[], CameraPose] | None = None,
        config: RunnerConfig = RunnerConfig(),
        progress: Progress | None = None,
        vehicle_says: VehicleSays | None = None,
        fixed_camera: bool = False,
        autopilot: Autopilot | None = None,
        steps: Iterator[int] | None = None,
    ) -> None:
        self.link = link
        self.autopilot = autopilot or for_vehicle(link.state.heartbeat)
        self.vehicle_says = vehicle_says or (lambda _text: None)
        self.fixed_camera = fixed_camera
        self.last_refusal = ""
        """The last command the vehicle refused, with its reason ("" if none)."""
        self._warnings: list[str] = []  # STATUSTEXTs of WARNING or worse, in order
        self.camera = camera
        self.mission = mission
        self.recorder = recorder
        self.live = live
        self.config = config
        self.progress = progress or (lambda _text, _t: None)
        self.scene_origin = scene_origin
        self.true_pose = true_pose
        self.step = 0
        self._steps = steps if steps is not None else itertools.count(1)
        """Numbers the observations fed to the mission (a fleet's runners share one: the
        members' observations then have one order)."""
        self.frames = 0
        self.coalesced = 0  # telemetry snapshots superseded before the mission saw them
        self.route: list[tuple[int, tuple[float, float, float]]] = []  # (time_boot_ms, ENU)
        self.results: list[Result] = []  # the mission's Result outputs
        self._queue: deque[Observation] = deque()
        self._pending: dict[int, tuple[int, int, int]] = {}
        self._unacked: dict[int, tuple[Command, int]] = {}  # MAV_CMD -> (command, last sent ms)
        """MAV_CMD -> (action id, vehicle ms, warnings heard when sent)."""
        self._gimbal = (0.0, 0.0)
        self._last: Telemetry | None = None
        self._lost_reported = 0.0
        self._link_lost = False
        self._last_heartbeat: float | None = None
        self._last_rx = 0.0
        self._target: GoTo | None = None  # the position target to send again, and when sent
        self._target_sent = 0.0
        self._target_left = math.inf  # how far the vehicle was from it then
        self.scene_offset = (0.0, 0.0)  # vehicle home in the scene's frame (east, north)

    # --- the loop ---------------------------------------------------------------------------

    def run(self) -> Outcome:
        self.begin()
        while not self.turn(self.config.poll_s):
            pass
        return self.finish()

    def begin(self) -> None:
        """Start the mission (its first outputs executed); then :meth:`turn` until done."""
        home = self.link.state.home
        if home is None:
            raise RuntimeError("Runner.run needs the vehicle's home (VehicleLink.wait_vehicle)")
        self.home = home
        if self.scene_origin is not None:
            east, north, _ = enu_from_geo(self.scene_origin, home)
            self.scene_offset = (east, north)
        self._handle(guarded(self.mission.start))
        self._last_rx = self.link.clock()

    def turn(self, timeout_s: float) -> bool:
        """One turn of the loop: feed the mission what is queued, read the link for up to
        ``timeout_s`` (0: what has arrived; a fleet steps the world itself), keep the link
        alive. True once the mission is done."""
        self._drain()
        if self.mission.done:
            return True
        msgs = self.link.poll(timeout_s)
        now = self.link.clock()
        if msgs:
            if self._link_lost:
                self._link_lost = False
                self._queue.append(LinkRestored(self._silent_s(now, self._last_rx)))
            self._last_rx = now
            for msg in msgs:
                self._on_message(msg)
        else:
            self._check_silence(now, self._last_rx)
        if self._last_heartbeat is None or now - self._last_heartbeat > self.config.heartbeat_s:
            self._heartbeat(now)
        if self._resend_due(now):
            assert self._target is not None
            self.autopilot.send(self.link, self._target, self.home)
        self.autopilot.tick(self.link, now, self.home)
        return False

    @property
    def busy(self) -> bool:
        """Whether observations wait to be fed to the mission (the next turn has work)."""
        return bool(self._queue)

    def finish(self) -> Outcome:
        assert self.mission.outcome is not None
        return self.mission.outcome

    def _resend_due(self, now: float) -> bool:
        """Whether to send the position target again: its interval is up, and the vehicle
        neither got there (within 1 m) nor came 0.5 m closer since it was last sent. A target
        sent again while the vehicle flies to it could arrive late (reordered) after the next
        one, and turn it back."""
        resend = self.config.target_resend_s
        if self._target is None or resend is None or now - self._target_sent < resend:
            return False
        if self._last is None:
            return True
        left = math.dist(self._last.pos_enu_m, self._target.pos_enu_m)
        closer = left < self._target_left - 0.5
        self._target_left, self._target_sent = left, now
        return left >= 1.0 and not closer

    def _drain(self) -> None:
        while self._queue and self.mission.outcome is None:
            obs = self._queue.popleft()
            self.step = next(self._steps)
            # A photo is encoded once, for the recording and the live view alike; without a
            # live view, the recording's writer encodes it (a writer process, off this path).
            png = None
            if isinstance(obs, Photo) and self.live is not None:
                png = png_encode(obs.image_rgb)
            if self.recorder is not None:
                self.recorder.observation(self.step, obs, png)
            if self.live is not None:
                self.live.observation(self.step, obs, png)
            outputs = guarded(self.mission.step, obs)
            self._handle(outputs)

    def _handle(self, outputs: list[Output]) -> None:
        if self.recorder is not None:
            self.recorder.outputs(self.step, outputs)
        if self.live is not None:
            self.live.outputs(self.step, outputs)
        for out in outputs:
            if isinstance(out, TakePhoto):
                self._queue.append(self._photo(out))
            elif isinstance(out, Command):
                self._command(out)
            elif isinstance(out, Event):
                self.progress(out.text, self.mission.last)
            elif isinstance(out, Result):
                self.results.append(out)

    # --- vehicle messages -------------------------------------------------------------------

    def _on_message(self, msg: object) -> None:
        kind = msg.get_type()  # type: ignore[attr-defined]
        if kind == "GLOBAL_POSITION_INT":
            t = telemetry(self.link, self._gimbal, self.autopilot)
            if t is not None:
                self._last = t
                if self._queue and isinstance(self._queue[-1], Telemetry):
                    # The mission wants the vehicle's state now, not a backlog of it: keep
                    # only the newest snapshot between two other observations.
                    self._queue[-1] = t
                    self.coalesced += 1
                else:
                    self._queue.append(t)
                if not t.landed:
                    self.route.append((t.time_boot_ms, t.pos_enu_m))
                self._expire_acks(t.time_boot_ms)
        elif kind == "COMMAND_ACK":
            self._on_ack(msg)
        elif kind == "HEARTBEAT":
            # Pace our heartbeat by the vehicle's: at any speed-up the vehicle hears us as
            # often as it speaks, so its ground-station failsafe never fires by accident.
            self._heartbeat(self.link.clock())
        elif (said := self.autopilot.vehicle_text(msg)) is not None:
            severity, text = said
            if self.recorder is not None:
                self.recorder.note(Level.INFO, f"vehicle: {text}", name="vehicle")
            if severity <= M.MAV_SEVERITY_WARNING:
                self._warnings.append(text)
                self.vehicle_says(f"vehicle: {text}")

    def _on_ack(self, msg: object) -> None:
        command, result = msg.command, msg.result  # type: ignore[attr-defined]
        pending = self._pending.get(command)
        if pending is None:
            return
        if result == M.MAV_RESULT_IN_PROGRESS:
            self._unacked.pop(command, None)  # it arrived: no need to send it again
            return
        del self._pending[command]
        self._unacked.pop(command, None)
        accepted = result == M.MAV_RESULT_ACCEPTED
        detail = ""
        if not accepted:
            # The vehicle's reason is the warning it sent since the command (ArduPilot sends
            # it just before the ACK, PX4 around it); DO_MOUNT_CONTROL without a mount has none.
            said = self._warnings[-1] if len(self._warnings) > pending[2] else ""
            detail = f"refused ({RESULT_NAMES.get(result, result)})" + (f": {said}" if said else "")
            self.last_refusal = f"{COMMAND_NAMES.get(command, str(command))} {detail}"
            self.vehicle_says(f"vehicle: {self.last_refusal}")
        final = result in (M.MAV_RESULT_DENIED, M.MAV_RESULT_UNSUPPORTED)
        self._queue.append(CommandResult(pending[0], accepted, detail, final))

    def _expire_acks(self, now_ms: int) -> None:
        limit_ms = self.config.ack_timeout_s * 1000.0
        resend = self.config.command_resend_s
        for command, (action_id, sent_ms, _) in list(self._pending.items()):
            if now_ms - sent_ms > limit_ms:
                del self._pending[command]
                self._unacked.pop(command, None)
                detail = f"no COMMAND_ACK in {self.config.ack_timeout_s:g} s"
                self._queue.append(CommandResult(action_id, False, detail))
            elif resend is not None and command in self._unacked:
                cmd, last_ms = self._unacked[command]
                if now_ms - last_ms > resend * 1000.0:
                    self.autopilot.send(self.link, cmd, self.home)
                    self._unacked[command] = (cmd, now_ms)

    def _check_silence(self, now: float, last_rx: float) -> None:
        c = self.config
        if now - last_rx < c.link_timeout_s:
            return
        if not self._link_lost or now - self._lost_reported >= c.link_report_s:
            self._link_lost = True
            self._lost_reported = now
            self._queue.append(LinkLost(self._silent_s(now, last_rx)))

    def _silent_s(self, now: float, last_rx: float) -> float:
        return round(now - last_rx, 3)

    def _heartbeat(self, now: float) -> None:
        self._last_heartbeat = now
        self.link.heartbeat()

    # --- executing outputs ------------------------------------------------------------------

    def _command(self, cmd: Command) -> None:
        if isinstance(cmd, SetGimbal):
            self._gimbal = (cmd.pitch_deg, cmd.yaw_deg)
        elif isinstance(cmd, GoTo):
            self._target, self._target_sent, self._target_left = cmd, self.link.clock(), math.inf
        else:  # a mode change, arming, a take-off: the target is no longer what is flown
            self._target = None
        sent = self.autopilot.send(self.link, cmd, self.home)
        if sent.mav_cmd == 0:
            self._queue.append(CommandResult(cmd.id, True, "sent"))
        else:
            now_ms = self._last.time_boot_ms if self._last is not None else 0
            self._pending[sent.mav_cmd] = (cmd.id, now_ms, len(self._warnings))
            self._unacked[sent.mav_cmd] = (cmd, now_ms)

    def _photo(self, cmd: TakePhoto) -> Photo:
        t = self._last
        assert t is not None  # the mission photographs only after telemetry
        pose = photo_pose(self.link, t, fixed_down=self.fixed_camera)
        at = self.true_pose() if self.true_pose is not None else pose
        (x, y, z), (dx, dy) = at.pos_enu_m, self.scene_offset
        image = self.camera.capture(
            CameraPose((x + dx, y + dy, z), at.heading_deg, at.pitch_deg, at.roll_deg)
        )
        photo = Photo(
            cmd.id, self.frames, cmd.tag, t.time_boot_ms, pose, self.camera.intrinsics, image
        )
        self.frames += 1
        return photo
