"""``uavtool record`` as a library call: listen to a vehicle someone else flies and record
everything the link carries, the vehicle's state, events and the camera's frames, until told
to stop. The same link, camera table and recording writer as ``uavtool fly``; no mission.

Passive by default: nothing is sent, so a UDP listener never even reveals itself. With
``direct`` the recorder sends its own heartbeat and stream requests (SET_MESSAGE_INTERVAL),
as a ground station would — but never while another ground station is heard on the link,
so it does not fight a pilot's ground station over stream rates.

A link that carries a fleet (``vehicles`` > 1) is read once (`FleetLink`); each vehicle is
recorded as one is, under ``/uavK`` and in its own local frame (around its own home), and the
MAVLink channels, which every frame crosses once, are shared.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from contextlib import ExitStack

from uavtool import __version__
from uavtool.camera import Intrinsics
from uavtool.errors import InputError, LinkError
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.link import VehicleLink, open_transport
from uavtool.recorder.config import RecordConfig, RecordSummary, Stop
from uavtool.recorder.fleet import FleetLink
from uavtool.recorder.frames import FrameTaker
from uavtool.recorder.listen import LISTEN_S, LinkTap, OneLink, VehicleSource, wait_vehicles
from uavtool.recorder.sink import LinkRecorder, PassiveRecorder
from uavtool.recorder.vehicle import RecordedVehicle
from uavtool.recording import Direction, LogLevel, RecordingError, RecordingWriter
from uavtool.recording.files import atomic_output
from uavtool.recording.fleet import CREW_METADATA, FLEET_METADATA, VehicleWriter
from uavtool.runner.camera import CameraSource, open_camera
from uavtool.world import Scene, load_scene, scene_to_dict

LOST_S = 10.0
"""With ``until_landed``: a vehicle silent this long is taken for lost (a dead vehicle never
lands on the link, and the recording went on for ever); one that reboots speaks sooner."""
MAX_VEHICLES = 254
"""MAVLink's system ids for vehicles: 1 … 254 (255 is the ground station's)."""
_IDLE_FLUSH_S = 1.0
_FLEET_CAMERAS = ("none", "sim")


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
    one = config.vehicles == 1
    w, h = config.size_px
    intrinsics = Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=config.hfov_deg)
    scene = load_scene(config.scene)
    with ExitStack() as stack:
        cameras: list[CameraSource] = []
        if config.camera != "none":  # one for each vehicle: --camera sim renders each's view
            for _ in range(config.vehicles):
                camera = open_camera(
                    config.camera, scene=scene, intrinsics=intrinsics, noise_seed=None
                )
                stack.callback(camera.close)
                cameras.append(camera)
        transport = open_transport(config.connect, timeout_s=config.timeout_s, keep_all=True)
        stack.callback(transport.close)
        tap = LinkTap()
        source: VehicleSource
        if one:
            source = OneLink(VehicleLink(transport, tap=tap, announce=False))
        else:
            source = FleetLink(
                transport,
                tap=tap,
                count=config.vehicles,
                ignored=lambda k: say(
                    f"heard vehicle sysid {k} too: not recorded (--vehicles {config.vehicles})"
                ),
            )
        origins = wait_vehicles(source, tap, config, say, stop_now)
        links = sorted(source.links, key=lambda link: link.target_system)
        sysids = [link.target_system for link in links]
        vehicle = (
            f"sysid {sysids[0]} on {source.name}"
            if one
            else f"sysids {', '.join(map(str, sysids))} on {source.name}"
        )
        for link in links:
            origin, origin_source = origins[link.target_system]
            where = f"{origin.lat_deg:.6f},{origin.lon_deg:.6f}"
            at = f"on {source.name}, origin {where} ({origin_source})"
            say(f"vehicle sysid {link.target_system} {at}")
        started: list[bool] = []
        partial = stack.enter_context(
            atomic_output(config.output, keep_on_error=lambda _exc: bool(started))
        )
        meta = _metadata(config, scene, [(k, *origins[k]) for k in sysids])
        writer = stack.enter_context(RecordingWriter(partial, metadata=meta))
        started.append(True)
        vehicles: list[RecordedVehicle] = []
        for i, link in enumerate(links):
            k = link.target_system
            origin = origins[k][0]
            recorder = PassiveRecorder(
                writer if one else VehicleWriter(writer, k), clock_ns=time.time_ns, origin=origin
            )
            taker = None
            if cameras:
                east, north, _ = enu_from_geo(scene.home, origin)
                taker = FrameTaker(
                    cameras[i],
                    renders=config.camera == "sim",
                    rate_hz=config.rate_hz,
                    photo_every_s=config.photo_every_s,
                    scene_offset_en_m=(east, north),
                )
            vehicles.append(RecordedVehicle(config, link, tap.watches[k], recorder, taker, one=one))
        channels = vehicles[0].recorder if one else LinkRecorder(writer, clock_ns=time.time_ns)
        for direction, frame, t_ns, decoded in tap.held:
            channels.counts[direction] += 1
            writer.write_mavlink(
                frame, direction=_direction(direction), log_time_ns=t_ns, decoded=decoded
            )
        tap.held.clear()
        tap.recorder = channels
        say(f"recording to {config.output} (Ctrl-C to stop)")
        loop = _Loop(config, source, writer, vehicles, stop_now)
        try:
            stop = loop.run()
        except LinkError as exc:  # the vehicle closed the link: what came before is kept
            for v in vehicles:
                v.note(LogLevel.ERROR, f"recording stopped: {exc}")
            kept_s = time.monotonic() - loop.start_s
            raise LinkError(
                f"{exc}; the {kept_s:.1f} s recorded until then are kept in {config.output}"
            ) from None
        for v in vehicles:
            v.finish()
        end_s = time.monotonic()
        duration_s = end_s - loop.start_s
        gaps_of = {v.sysid: v.gaps(stop, loop.start_s, end_s, lost_s=LOST_S) for v in vehicles}
        gaps = tuple(gap for v in vehicles for gap in gaps_of[v.sysid])
        for v in vehicles:
            for gap in gaps_of[v.sysid]:
                v.note(LogLevel.WARNING, f"recording incomplete: {gap}")
            v.note(LogLevel.INFO, f"recording stopped: {stop.value}")
        frames = sum(v.recorder.counts["frames"] for v in vehicles)
        photos = sum(v.recorder.counts["photos"] for v in vehicles)
        max_pose_dt_ms = max(v.recorder.max_pose_dt_ms for v in vehicles)
        writer.add_metadata(
            "record_result",
            {
                "stopped": stop.value,
                "duration_s": f"{duration_s:.1f}",
                "frames": str(frames),
                "photos": str(photos),
                "max_pose_dt_ms": str(max_pose_dt_ms),
                "gaps": "; ".join(gaps),
            },
        )
        summaries = tuple(v.summary(gaps_of[v.sysid]) for v in vehicles)
        if not one:
            for s in summaries:
                writer.add_metadata(
                    f"record_result.uav{s.sysid}",
                    {
                        "telemetry": str(s.telemetry),
                        "frames": str(s.frames),
                        "photos": str(s.photos),
                        "events": str(s.events),
                        "gaps": "; ".join(s.gaps),
                    },
                )
    return RecordSummary(
        config.output,
        stop,
        vehicle,
        duration_s,
        channels.counts["in"],
        channels.counts["out"],
        sum(s.telemetry for s in summaries),
        frames,
        photos,
        sum(s.events for s in summaries),
        max_pose_dt_ms,
        gaps,
        summaries,
    )


class _Loop:
    def __init__(
        self,
        config: RecordConfig,
        source: VehicleSource,
        writer: RecordingWriter,
        vehicles: list[RecordedVehicle],
        stop_now: Callable[[], bool],
    ) -> None:
        self.config = config
        self.source = source
        self.writer = writer
        self.vehicles = vehicles
        self.stop_now = stop_now
        self.start_s = time.monotonic()
        for v in vehicles:
            v.last_rx_s = self.start_s
        self._last_hb_s: float | None = None

    def run(self) -> Stop:
        c, clock = self.config, time.monotonic
        last_flush = clock()
        try:
            while True:
                got = {link.target_system: msgs for link, msgs in self.source.poll(0.02)}
                now = clock()
                for v in self.vehicles:
                    v.heard(got.get(v.sysid, []), now)
                for v in self.vehicles:
                    v.tell(now)
                if c.direct:
                    self._speak(now)
                last_rx = max(v.last_rx_s for v in self.vehicles)
                if now - last_rx >= _IDLE_FLUSH_S and now - last_flush >= _IDLE_FLUSH_S:
                    self.writer.flush()  # a quiet link: put the last chunk on disk
                    last_flush = now
                stop = self._stop(now)
                if stop is not None:
                    return stop
        except KeyboardInterrupt:
            return Stop.INTERRUPTED

    def _stop(self, now: float) -> Stop | None:
        c = self.config
        if c.until_landed:
            for v in self.vehicles:
                if not v.lost and now - v.last_rx_s >= LOST_S:
                    v.lost = True
                    v.note(LogLevel.WARNING, f"link: nothing heard for {LOST_S:g} s: lost")
            # Every vehicle that flew is down (or lost), and none of the others is armed.
            flew = [v for v in self.vehicles if v.watch.airborne_seen]
            idle = all(v.lost or not v.armed for v in self.vehicles if v not in flew)
            if flew and idle and all(v.over or v.lost for v in flew):
                return Stop.LANDED if any(v.over for v in flew) else Stop.VEHICLE_LOST
            if all(v.lost for v in self.vehicles):
                return Stop.VEHICLE_LOST
        if c.duration_s is not None and now - self.start_s >= c.duration_s:
            return Stop.DURATION
        if self.stop_now():
            return Stop.INTERRUPTED
        return None

    def _speak(self, now: float) -> None:
        # Listen for a ground station's heartbeat (1 Hz) before saying anything.
        if now - self.start_s < LISTEN_S or any(v.watch.gcs_present(now) for v in self.vehicles):
            return
        if self._last_hb_s is None or now - self._last_hb_s >= 1.0:
            self.source.heartbeat()
            for v in self.vehicles:
                if not v.requested:
                    v.link.request_streams()
                    v.requested = True
            self._last_hb_s = now


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
    if not 1 <= config.vehicles <= MAX_VEHICLES:
        raise InputError(f"--vehicles {config.vehicles}: expected 1 … {MAX_VEHICLES}")
    if config.vehicles > 1 and config.camera not in _FLEET_CAMERAS:
        raise InputError(
            f"--camera {config.camera} with --vehicles {config.vehicles}: one camera cannot be "
            "every vehicle's; --camera sim renders each vehicle's own view, none records no "
            "images (a real camera per vehicle is not built yet)"
        )


def _direction(text: str) -> Direction:
    return Direction.IN if text == "in" else Direction.OUT


def _metadata(
    config: RecordConfig, scene: Scene, vehicles: list[tuple[int, GeoPoint, str]]
) -> dict[str, dict[str, str]]:
    """The ``record`` record (and, for a fleet, ``fleet`` and ``crew``); ``vehicles``: each
    one's system id, origin and where the origin came from, in system-id order."""
    record = {
        "tool_version": __version__,
        "connect": config.connect,
        "direct": json.dumps(config.direct),
        "camera": config.camera,
        "rate_hz": json.dumps(config.rate_hz),
        "photo_every_s": json.dumps(config.photo_every_s),
        "clock": "wall",
    }
    meta = {"record": record}
    if len(vehicles) == 1:
        sysid, origin, origin_source = vehicles[0]
        record["vehicle_sysid"] = str(sysid)
        record["origin"] = json.dumps([origin.lat_deg, origin.lon_deg, origin.alt_amsl_m])
        record["origin_source"] = origin_source
    else:
        record["vehicle_sysids"] = json.dumps([k for k, _, _ in vehicles])
        record["origins"] = json.dumps(
            [[o.lat_deg, o.lon_deg, o.alt_amsl_m] for _, o, _ in vehicles]
        )
        record["origin_sources"] = json.dumps([s for _, _, s in vehicles])
        meta[FLEET_METADATA] = {"vehicles": str(len(vehicles))}
        # Each vehicle's home (its frame's origin) in the frame of the first's, as a fleet
        # that `fly` flies has them: where a viewer places each vehicle's frame.
        first = vehicles[0][1]
        homes = [[round(c, 3) for c in enu_from_geo(first, o)[:2]] for _, o, _ in vehicles]
        meta[CREW_METADATA] = {"homes_en_m": json.dumps(homes)}
    if config.camera == "sim":  # the ground truth the frames were rendered from
        meta["scene"] = {"name": scene.name, "json": json.dumps(scene_to_dict(scene))}
    return meta
