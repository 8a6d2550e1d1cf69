"""``uavtool record`` as a library call: listen to a vehicle someone else flies and record
everything the link carries, the vehicle's state, events and the camera's frames, until told
to stop. The same link, camera table and recording writer as ``uavtool fly``; no mission.

Passive by default: nothing is sent, so a UDP listener never even reveals itself. With
``direct`` the recorder sends its own heartbeat and stream requests (SET_MESSAGE_INTERVAL),
as a ground station would — but never while another ground station is heard on the link,
so it does not fight a pilot's ground station over stream rates.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Any

from uavtool import __version__
from uavtool.autopilot import for_vehicle
from uavtool.camera import Intrinsics
from uavtool.errors import InputError, LinkError
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.link import VehicleLink, open_transport
from uavtool.recorder.config import RecordConfig, RecordSummary, Stop
from uavtool.recorder.frames import FrameTaker, PoseTrack
from uavtool.recorder.sink import PassiveRecorder
from uavtool.recorder.watch import Event, VehicleWatch, frame_ids
from uavtool.recording import Direction, LogLevel, RecordingError, RecordingWriter
from uavtool.recording.files import atomic_output
from uavtool.runner.camera import open_camera
from uavtool.runner.vehicle import telemetry
from uavtool.world import Scene, load_scene, scene_to_dict

SILENCE_S = 3.0
"""A link silent this long gets an event (and another when it speaks again)."""
LOST_S = 10.0
"""With ``until_landed``: a vehicle silent this long is taken for lost (a dead vehicle never
lands on the link, and the recording went on for ever); one that reboots speaks sooner."""
LISTEN_S = 1.5
"""With ``direct``: how long to listen for another ground station before speaking."""
_IDLE_FLUSH_S = 1.0
_STREAM_REQUEST_S = 2.0


@dataclass(slots=True)
class _Tap:
    """Every frame crossing the link: held until the file exists, then written; frames from
    other systems also go to the watch."""

    held: list[tuple[str, bytes, int, Any]] = field(default_factory=list)
    recorder: PassiveRecorder | None = None
    watch: VehicleWatch | None = None
    clock: Callable[[], float] = time.monotonic

    def __call__(self, direction: str, frames: list[bytes], decoded: list[Any] | None) -> None:
        now_ns = time.time_ns()
        for i, frame in enumerate(frames):
            msg = None if decoded is None else decoded[i]
            if self.recorder is not None:
                self.recorder.mavlink(direction, frame, msg)
            else:
                self.held.append((direction, frame, now_ns, msg))
            watch = self.watch
            if watch is not None and direction == "in" and frame_ids(frame)[0] != watch.target[0]:
                watch.foreign(frame, self.clock())


def record(
    config: RecordConfig,
    *,
    status: Callable[[str], None] | None = None,
    stop_requested: Callable[[], bool] | None = None,
) -> RecordSummary:
    """Record until Ctrl-C (or ``stop_requested()``), ``duration_s`` or, with
    ``until_landed``, the vehicle's landing and disarm. Raises LinkError (exit 2) when no
    vehicle is heard within ``timeout_s``, InputError for bad options; the file then is not
    created. Once recording, the file is always closed whole; a write that fails (a full
    disk) is a RecordingError naming the file that keeps what was recorded before it."""
    started_ns = time.time_ns()
    try:
        return _record(config, status=status, stop_requested=stop_requested)
    except RecordingError as exc:
        kept = config.output.exists() and config.output.stat().st_mtime_ns >= started_ns
        if exc.path == str(config.output) or not kept:
            raise
        # The writer named its partial file; what it held is kept under the name asked for.
        raise RecordingError(
            config.output,
            f"{exc.problem}; what was recorded until then is kept here "
            f"(`uavtool info {config.output}` checks it)",
        ) from None


def _record(
    config: RecordConfig,
    *,
    status: Callable[[str], None] | None,
    stop_requested: Callable[[], bool] | None,
) -> RecordSummary:
    say = status or (lambda _text: None)
    stop_now = stop_requested or (lambda: False)
    _check(config)
    w, h = config.size_px
    intrinsics = Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=config.hfov_deg)
    scene = load_scene(config.scene)
    with ExitStack() as stack:
        camera = None
        if config.camera != "none":
            camera = open_camera(config.camera, scene=scene, intrinsics=intrinsics, noise_seed=None)
            stack.callback(camera.close)
        transport = open_transport(config.connect, timeout_s=config.timeout_s)
        stack.callback(transport.close)
        tap = _Tap()
        link = VehicleLink(transport, tap=tap, announce=False)
        origin, origin_source = _wait_vehicle(link, tap, config, say, stop_now)
        vehicle = f"sysid {link.target_system} on {link.name}"
        where = f"{origin.lat_deg:.6f},{origin.lon_deg:.6f}"
        say(f"vehicle {vehicle}, origin {where} ({origin_source})")
        started: list[bool] = []
        partial = stack.enter_context(
            atomic_output(config.output, keep_on_error=lambda _exc: bool(started))
        )
        meta = _metadata(config, scene, link, origin, origin_source)
        writer = stack.enter_context(RecordingWriter(partial, metadata=meta))
        started.append(True)
        recorder = PassiveRecorder(writer, clock_ns=time.time_ns, origin=origin)
        for direction, frame, t_ns, decoded in tap.held:
            recorder.counts[direction] += 1
            writer.write_mavlink(
                frame, direction=_direction(direction), log_time_ns=t_ns, decoded=decoded
            )
        tap.held.clear()
        tap.recorder = recorder
        assert tap.watch is not None
        taker = None
        if camera is not None:
            east, north, _ = enu_from_geo(scene.home, origin)
            taker = FrameTaker(
                camera,
                renders=config.camera == "sim",
                rate_hz=config.rate_hz,
                photo_every_s=config.photo_every_s,
                scene_offset_en_m=(east, north),
            )
        say(f"recording to {config.output} (Ctrl-C to stop)")
        loop = _Loop(config, link, tap.watch, recorder, taker, origin, stop_now)
        try:
            stop = loop.run()
        except LinkError as exc:  # the vehicle closed the link: what came before is kept
            recorder.event(Event(LogLevel.ERROR, f"recording stopped: {exc}", "recorder"))
            kept_s = time.monotonic() - loop.start_s
            raise LinkError(
                f"{exc}; the {kept_s:.1f} s recorded until then are kept in {config.output}"
            ) from None
        for f in taker.finish(loop.track) if taker is not None else []:
            recorder.frame(f)
        end_s = time.monotonic()
        duration_s = end_s - loop.start_s
        gaps = loop.gaps(stop, end_s)
        for gap in gaps:
            recorder.event(Event(LogLevel.WARNING, f"recording incomplete: {gap}", "recorder"))
        recorder.event(Event(LogLevel.INFO, f"recording stopped: {stop.value}", "recorder"))
        c = recorder.counts
        writer.add_metadata(
            "record_result",
            {
                "stopped": stop.value,
                "duration_s": f"{duration_s:.1f}",
                "frames": str(c["frames"]),
                "photos": str(c["photos"]),
                "max_pose_dt_ms": str(recorder.max_pose_dt_ms),
                "gaps": "; ".join(gaps),
            },
        )
    return RecordSummary(
        config.output,
        stop,
        vehicle,
        duration_s,
        c["in"],
        c["out"],
        c["telemetry"],
        c["frames"],
        c["photos"],
        c["events"],
        recorder.max_pose_dt_ms,
        gaps,
    )


class _Loop:
    def __init__(
        self,
        config: RecordConfig,
        link: VehicleLink,
        watch: VehicleWatch,
        recorder: PassiveRecorder,
        taker: FrameTaker | None,
        origin: GeoPoint,
        stop_now: Callable[[], bool],
    ) -> None:
        self.config = config
        self.link = link
        self.watch = watch
        self.recorder = recorder
        self.taker = taker
        self.origin = origin
        self.stop_now = stop_now
        self.track = PoseTrack()
        self.start_s = time.monotonic()
        self._vehicle_home = link.state.home
        self._last_hb_s: float | None = None
        self._requested = False
        self.last_rx_s = self.start_s

    def gaps(self, stop: Stop, end_s: float) -> tuple[str, ...]:
        """What the recording lacks of what was asked for, one line each (the vehicle gone
        silent before a --duration or --until-landed end, a camera that stalled or failed);
        nothing for Ctrl-C, which ends it where the user wanted."""
        if stop is Stop.INTERRUPTED:
            return ()
        found = []
        silent_s = end_s - self.last_rx_s
        if silent_s >= LOST_S:
            found.append(
                f"link: nothing heard from the vehicle for the last {silent_s:.1f} s "
                f"(since {self.last_rx_s - self.start_s:.1f} s in)"
            )
        if self.taker is not None:
            camera = self.taker.gap(start_s=self.start_s, end_s=end_s)
            if camera is not None:
                found.append(camera)
        return tuple(found)

    def run(self) -> Stop:
        c, link, clock = self.config, self.link, time.monotonic
        last_rx = last_flush = clock()
        silent = False
        try:
            while True:
                msgs = link.poll(0.02)
                now = clock()
                if msgs:
                    if silent:
                        self._note(LogLevel.INFO, "link: the vehicle speaks again")
                    last_rx, silent = now, False
                    self.last_rx_s = now
                elif not silent and now - last_rx >= SILENCE_S:
                    silent = True
                    self._note(LogLevel.WARNING, f"link: nothing heard for {SILENCE_S:g} s")
                landed = False
                for msg in msgs:
                    landed |= self._message(msg, now)
                for event in self.watch.take_events():
                    self.recorder.event(event)
                self._camera(now)
                if c.direct:
                    self._speak(now)
                if now - last_rx >= _IDLE_FLUSH_S and now - last_flush >= _IDLE_FLUSH_S:
                    self.recorder.writer.flush()  # a quiet link: put the last chunk on disk
                    last_flush = now
                if landed and c.until_landed:
                    return Stop.LANDED
                if c.until_landed and now - last_rx >= LOST_S:
                    self._note(LogLevel.WARNING, f"link: nothing heard for {LOST_S:g} s: lost")
                    return Stop.VEHICLE_LOST
                if c.duration_s is not None and now - self.start_s >= c.duration_s:
                    return Stop.DURATION
                if self.stop_now():
                    return Stop.INTERRUPTED
        except KeyboardInterrupt:
            return Stop.INTERRUPTED

    def _message(self, msg: object, now: float) -> bool:
        """Record what ``msg`` tells; True when the flight is over."""
        self.watch.vehicle(msg, now)
        kind = msg.get_type()  # type: ignore[attr-defined]
        state = self.link.state
        if kind == "HOME_POSITION" and state.home != self._vehicle_home:
            self._vehicle_home = state.home
            if state.home is not None:
                e, n, u = enu_from_geo(self.origin, state.home)
                self._note(LogLevel.INFO, f"vehicle home now at {e:.1f} E {n:.1f} N {u:.1f} U m")
        if kind != "GLOBAL_POSITION_INT":
            return False
        # Poses stay in one frame for the whole file, whatever the vehicle's home does.
        state.home = self.origin
        autopilot = self.watch.autopilot or for_vehicle(self.link.state.heartbeat)
        t = telemetry(self.link, (self.config.gimbal_pitch_deg, 0.0), autopilot)
        state.home = self._vehicle_home
        if t is None:
            return False
        self.track.add(t, now)
        self.recorder.telemetry(t)
        return self.watch.flight_over(armed=t.armed, landed=t.landed)

    def _camera(self, now: float) -> None:
        triggers = self.watch.take_triggers()
        if self.taker is None:
            for trigger in triggers:
                self._note(LogLevel.INFO, f"photo trigger ({trigger}): no camera", "camera")
            return
        for f in self.taker.tick(now, self.track, triggers):
            self.recorder.frame(f)
        for event in self.taker.events:
            self.recorder.event(event)
        self.taker.events.clear()

    def _speak(self, now: float) -> None:
        # Listen for a ground station's heartbeat (1 Hz) before saying anything.
        if now - self.start_s < LISTEN_S or self.watch.gcs_present(now):
            return
        if self._last_hb_s is None or now - self._last_hb_s >= 1.0:
            self.link.heartbeat()
            if not self._requested:
                self.link.request_streams()
                self._requested = True
            self._last_hb_s = now

    def _note(self, level: LogLevel, text: str, source: str = "recorder") -> None:
        self.recorder.event(Event(level, text, source))


def _wait_vehicle(
    link: VehicleLink,
    tap: _Tap,
    config: RecordConfig,
    say: Callable[[str], None],
    stop_now: Callable[[], bool],
) -> tuple[GeoPoint, str]:
    """Listen until a vehicle's heartbeat and position are known (and its home, for up to
    ``home_wait_s`` more); the origin of the recording's local frame and where it came from."""
    clock = time.monotonic
    deadline = clock() + config.timeout_s
    found_s: float | None = None
    positioned_s: float | None = None
    last_request: float | None = None
    while True:
        now = clock()
        if link.target_system and tap.watch is None:
            tap.watch = VehicleWatch(link.target_system, link.target_component)
            found_s = now
            say(f"heard vehicle sysid {link.target_system}")
        state = link.state
        if state.position is not None and state.heartbeat is not None:
            positioned_s = positioned_s or now
            if state.home is not None:
                return state.home, "HOME_POSITION"
            if now - positioned_s >= config.home_wait_s:
                p = state.position
                return GeoPoint(p.lat / 1e7, p.lon / 1e7, (p.alt - p.relative_alt) / 1000.0), (
                    "first fix: no HOME_POSITION heard"
                )
        if stop_now():
            raise KeyboardInterrupt  # before anything was recorded: no file
        if now > deadline:
            what = "heartbeat" if not link.target_system else "position"
            hint = (
                ""
                if config.direct
                else "; nothing was sent (passive): is the vehicle or its router sending to "
                "this address? --direct asks for its streams"
            )
            raise LinkError(
                f"{link.name}: no {what} from a vehicle in {config.timeout_s:g} s{hint}"
            )
        watch = tap.watch
        quiet = watch is None or watch.gcs_present(now)
        # direct: ask for the streams once we have listened long enough to hear a ground station
        listened = found_s is not None and now - found_s >= LISTEN_S
        due = last_request is None or now - last_request >= _STREAM_REQUEST_S
        if config.direct and listened and not quiet and due:
            link.heartbeat()
            link.request_streams()
            last_request = now
        for msg in link.poll(0.05):
            if tap.watch is not None:
                tap.watch.vehicle(msg, clock())


def _check(config: RecordConfig) -> None:
    for name, value in (
        ("--rate", config.rate_hz),
        ("--photo-every", config.photo_every_s),
        ("--timeout", config.timeout_s),
    ):
        if not math.isfinite(value) or value < 0:
            raise InputError(f"{name} {value:g}: expected a number ≥ 0")
    if config.duration_s is not None and not (
        math.isfinite(config.duration_s) and config.duration_s > 0
    ):
        raise InputError(f"--duration {config.duration_s:g}: expected a number of seconds > 0")
    if not -90.0 <= config.gimbal_pitch_deg <= 90.0:
        raise InputError(f"--gimbal-pitch {config.gimbal_pitch_deg:g}: expected -90 … 90 degrees")


def _direction(text: str) -> Direction:
    return Direction.IN if text == "in" else Direction.OUT


def _metadata(
    config: RecordConfig, scene: Scene, link: VehicleLink, origin: GeoPoint, origin_source: str
) -> dict[str, dict[str, str]]:
    meta = {
        "record": {
            "tool_version": __version__,
            "connect": config.connect,
            "direct": json.dumps(config.direct),
            "camera": config.camera,
            "rate_hz": json.dumps(config.rate_hz),
            "photo_every_s": json.dumps(config.photo_every_s),
            "clock": "wall",
            "vehicle_sysid": str(link.target_system),
            "origin": json.dumps([origin.lat_deg, origin.lon_deg, origin.alt_amsl_m]),
            "origin_source": origin_source,
        },
    }
    if config.camera == "sim":  # the ground truth the frames were rendered from
        meta["scene"] = {"name": scene.name, "json": json.dumps(scene_to_dict(scene))}
    return meta
