"""``uavtool fly`` as a library call: connect (or start the built-in SITL), fly the mission,
record it, and summarise the flight.

The built-in vehicle always flies in lockstep with the runner (:mod:`uavtool.sitl.lockstep`):
the flight, and its recording byte for byte, depend only on the :class:`FlyConfig`, never on
the speed-up or the machine. Any other vehicle flies on the wall clock.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from uavtool import __version__
from uavtool.autopilot import Autopilot, for_vehicle
from uavtool.camera import CameraPose, Intrinsics
from uavtool.errors import InputError, LinkError
from uavtool.flight import CONNECT_BUILTIN, FlightDescription
from uavtool.images import png_decode, png_encode
from uavtool.link import VehicleLink
from uavtool.mission import FlightMission, Level, MissionInputs, Outcome, SearchMission
from uavtool.mission.outputs import Result
from uavtool.mission.params import to_dict, with_overrides
from uavtool.plugins import DEFAULT, MissionRef, create_mission, resolve
from uavtool.recording.cores import core_to_spare
from uavtool.recording.errors import RecordingError
from uavtool.recording.files import atomic_output
from uavtool.recording.process import ProcessWriter
from uavtool.runner.backends import open_backend
from uavtool.runner.camera import open_camera
from uavtool.runner.evaluate import Evaluation, evaluate
from uavtool.runner.live import LiveView
from uavtool.runner.params import set_vehicle_params
from uavtool.runner.placement import SCENE_ORIGINS
from uavtool.runner.preflight import check_camera, check_fence, check_gimbal, check_home
from uavtool.runner.record import MissionRecorder
from uavtool.runner.runner import Progress, Runner
from uavtool.world import Scene, load_scene, render, scene_to_dict

if TYPE_CHECKING:
    from uavtool.recording.protocol import MessageWriter

_TARGET_VIEW_M = 30.0  # the default target picture: from this far above its roof


@dataclass(frozen=True, slots=True)
class FlyConfig:
    """What ``uavtool fly`` options set. ``connect`` None starts the built-in SITL."""

    connect: str | None = None
    scene: str | Scene = "paper"
    """A built-in scene's name, a scene file, or a loaded scene."""
    target: Path | None = None
    camera: str = "sim"
    speedup: float | None = None
    """Cap on the built-in vehicle's pace, vehicle seconds per wall second; None: as fast as
    the CPU allows. It never changes the flight."""
    record: Path | None = None
    """None: ``recordings/<UTC time>.mcap``."""
    no_record: bool = False
    record_in_process: bool | None = None
    """Where the recording is written: True on the flight's own thread (`RecordingWriter`),
    False in a process of its own (`ProcessWriter`: off the flight's path, but more work in
    all), None: in a process of its own when a core is free for it (`core_to_spare`). The
    file is the same either way. Sweeps say True: their flights keep every core busy."""
    mission: str = DEFAULT
    """Which mission flies: a registered name (``uavtool missions``) or ``module:Class``."""
    params: Any = None
    """The mission's parameters (an instance of its ``Params``); None: its defaults."""
    vehicle_params: tuple[tuple[str, float], ...] = ()
    seed: int = 0
    noise: bool = False
    wind: tuple[float, float] = (0.0, 0.0)
    link_outages_s: tuple[tuple[float, float], ...] = ()
    hfov_deg: float = 60.0
    size_px: tuple[int, int] = (640, 480)
    connect_timeout_s: float = 30.0
    rerun: str | None = None
    """Stream live to Rerun: ``"spawn"`` (native viewer), ``"web"`` or a ``.rrd`` path."""
    rerun_web_port: int | None = None
    """With ``rerun="web"``: the web viewer's port; None: Rerun's default (9090)."""
    rerun_grpc_port: int | None = None
    """With ``rerun="web"``: the port the viewer reads the flight from; None: 9876."""
    no_gimbal: bool = False
    """The camera is fixed straight down: no gimbal check, the search only (see
    ``MissionParams.gimbal``). The built-in vehicle then boots without a mount."""
    connects: tuple[str, ...] = ()
    """A fleet of external vehicles, one connection string each (``fly --connect URL
    --connect URL …``); empty: built-in vehicles."""
    vehicles: int = 1
    """How many built-in vehicles fly (more than one: a fleet, :func:`uavtool.runner.fleet.
    fly_fleet`)."""
    offset_line: tuple[float, float] | None = (90.0, 10.0)
    homes_m: tuple[tuple[float, float], ...] = ()
    """A fleet's homes, one per built-in vehicle: metres east and north of the scene's home
    (``--home E,N``); empty: on ``offset_line``."""
    """A fleet's homes: vehicle i's is i × spacing (m) from the scene's home along the bearing
    (degrees): (bearing, spacing); None: the first line clear of every building."""
    scene_origin: str = "vehicle"
    """With the sim camera and another vehicle: ``"vehicle"`` puts the scene at the vehicle's
    home, ``"scene"`` keeps the scene's own geographic origin (refused when the vehicle is
    beyond the scene's extent)."""


@dataclass(frozen=True, slots=True)
class FlightSummary:
    outcome: Outcome
    evaluation: Evaluation
    route_length_m: float
    flight_time_s: float
    frames: int
    recording: Path | None
    wall_time_s: float
    vehicle: str
    vehicle_time_s: float
    """Vehicle time from the first observation to the end of the mission."""
    clearance_m: float | None
    """Least gap between the vehicle's body and any building of the scene while airborne (the
    built-in vehicle's own, exact; from the telemetry for another vehicle with the sim
    camera; None without a scene)."""
    clearance_building: str
    flight_wall_s: float
    """Wall time of the same span (the mission itself, without start-up)."""
    last_refusal: str = ""
    """The last command the vehicle refused, with its reason ("" if none)."""
    stale_dropped: tuple[tuple[str, int], ...] = ()
    """Messages dropped as older than one already taken (late on the link), per message name;
    the recording keeps them."""
    mission: str = DEFAULT
    """The mission's name."""
    searched: bool = True
    """Whether it was the built-in search (the outcome's visits, match and model mean
    something)."""
    results: tuple[Result, ...] = ()
    """The mission's :class:`Result` outputs, in order."""


def default_recording_path(now: datetime | None = None) -> Path:
    stamp = (now or datetime.now(UTC)).strftime("%Y%m%dT%H%M%SZ")
    return Path("recordings") / f"{stamp}.mcap"


def target_picture(scene: Scene, intrinsics: Intrinsics) -> bytes:
    """The scene's target building alone, photographed from above (PNG): on the scene's
    ground, in its light, without the other buildings and the ground's areas (a lawn
    beside it would be a second shape in the picture)."""
    building = scene.target_building
    xs = [x for blk in building.blocks for x, _ in blk.footprint_enu_m]
    ys = [y for blk in building.blocks for _, y in blk.footprint_enu_m]
    top = max(blk.top_m for blk in building.blocks)
    centre = ((min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0, top + _TARGET_VIEW_M)
    alone = dataclasses.replace(scene, buildings=(building,), ground_areas=())
    return png_encode(render(alone, CameraPose(centre, 0.0, -90.0), intrinsics))


@dataclass(frozen=True, slots=True)
class Setup:
    """What a flight's inputs come to before any vehicle is reached: the config with the
    mission's parameters filled in, the scene, the camera's intrinsics and the target
    picture (PNG and pixels; None when the mission needs none)."""

    config: FlyConfig
    scene: Scene
    intrinsics: Intrinsics
    target_png: bytes | None
    target_rgb: Any


def prepare(config: FlyConfig, mission_cls: type[FlightMission]) -> Setup:
    """Check and complete a flight's inputs for ``mission_cls`` (one vehicle's or a fleet's):
    its parameters (``--no-gimbal`` applied), its scene loaded, its target picture read or
    rendered. InputError names what is wrong."""
    params = config.params if config.params is not None else mission_cls.params_type()
    if not isinstance(params, mission_cls.params_type):
        raise InputError(
            f"--mission {config.mission}: parameters of type {type(params).__name__}, "
            f"expected {mission_cls.params_type.__name__}"
        )
    if config.no_gimbal:
        params = with_overrides(params, {f"{mission_cls.flight_group}.gimbal": False})
    config = dataclasses.replace(config, params=params)
    scene = config.scene if isinstance(config.scene, Scene) else load_scene(config.scene)
    w, h = config.size_px
    intrinsics = Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=config.hfov_deg)
    target_png: bytes | None = None
    if config.target:
        target_png = _read_target(config.target)
    elif mission_cls.needs_target:
        target_png = target_picture(scene, intrinsics)
    target_rgb = None if target_png is None else png_decode(target_png, where="target")
    return Setup(config, scene, intrinsics, target_png, target_rgb)


def fly(
    config: FlyConfig,
    *,
    progress: Progress | None = None,
    status: Callable[[str], None] | None = None,
    vehicle_says: Callable[[str], None] | None = None,
    autopilot_for: Callable[[object], Autopilot] = for_vehicle,
) -> FlightSummary:
    """Fly one mission; raises InputError on bad input or a failed pre-flight check
    (:class:`PreflightError`, before arming), LinkError when the vehicle cannot be reached.
    ``progress`` hears each mission event, ``status`` the set-up steps, ``vehicle_says`` the
    vehicle's warnings and refusals as they arrive. ``autopilot_for`` picks the adapter from
    the vehicle's HEARTBEAT (e.g. ``lambda _: PX4(movement="offboard")``)."""
    say = status or (lambda _text: None)
    wall0 = time.monotonic()
    if config.scene_origin not in SCENE_ORIGINS:
        raise InputError(f"--scene-origin {config.scene_origin}: expected vehicle or scene")
    mission_cls, ref = resolve(config.mission)
    setup = prepare(config, mission_cls)
    config, scene, intrinsics = setup.config, setup.scene, setup.intrinsics
    params, target_png, target_rgb = config.params, setup.target_png, setup.target_rgb
    mission = create_mission(mission_cls, params, MissionInputs(target_rgb=target_rgb))
    camera = open_camera(
        config.camera,
        scene=scene,
        intrinsics=intrinsics,
        noise_seed=config.seed if config.noise else None,
    )
    with ExitStack() as stack:
        stack.callback(camera.close)
        backend = stack.enter_context(open_backend(config, scene, say))
        clock, clock_ns = backend.clock, backend.clock_ns
        flown: list[bool] = []  # set once the mission starts: from then on the file is kept
        writer, path = open_recording(stack, config, scene, ref, target_png is not None, flown)
        recorder = None
        if writer is not None:
            recorder = MissionRecorder(writer, clock_ns=clock_ns)
            if target_png is not None:
                recorder.target(target_png)
        live = None
        if config.rerun is not None:
            live = LiveView(
                config.rerun,
                web_port=config.rerun_web_port,
                grpc_port=config.rerun_grpc_port,
                scene=scene if config.camera == "sim" else None,
                params=to_dict(config.params),
                target_png=target_png,
                clock_ns=clock_ns,
            )
            stack.callback(live.close)
            if live.url:
                say(f"Rerun web viewer at {live.url}")
        link = VehicleLink(
            backend.transport,
            tap=recorder.mavlink if recorder else None,
            clock=clock,
            announce=backend.announce,
        )
        link.wait_vehicle(config.connect_timeout_s)
        home = link.state.home
        assert home is not None
        autopilot = autopilot_for(link.state.heartbeat)
        say(
            f"vehicle {link.target_system} ({autopilot.name}) on {link.name}, "
            f"home {home.lat_deg:.6f},{home.lon_deg:.6f}"
        )
        if live is not None:
            live.home(home)
        if recorder is not None:
            recorder.home = home
            recorder.note(Level.INFO, f"connected to sysid {link.target_system} on {link.name}")
        learnt = autopilot.prepare(link)
        if learnt:
            say(learnt)
        if config.vehicle_params:
            set_vehicle_params(link, config.vehicle_params, autopilot)
        check_home(link)
        if config.camera != "sim":
            check_camera(camera)
        if not config.no_gimbal:
            check_gimbal(link, autopilot)
        check_fence(link, autopilot, mission_cls.envelope(params, camera.intrinsics))
        simulated = config.camera == "sim"
        runner = Runner(
            link,
            camera,
            mission,
            recorder=recorder,
            live=live,
            scene_origin=backend.scene_origin(scene, home, say) if simulated else None,
            true_pose=backend.true_pose,
            progress=progress,
            vehicle_says=vehicle_says,
            fixed_camera=config.no_gimbal,
            autopilot=autopilot,
            config=backend.runner_config,
        )
        flight_wall0, vehicle0 = time.perf_counter(), clock()
        flown.append(True)
        try:
            outcome = runner.run()
        except KeyboardInterrupt:
            _abort(link, autopilot, recorder, "interrupted by the user: RTL sent")
            raise
        except Exception as exc:
            _return_home(link, autopilot)  # never leave the vehicle flying a stale command
            _failed(recorder, exc)
            raise
        flight_wall_s, vehicle_s = time.perf_counter() - flight_wall0, clock() - vehicle0
        if writer is not None:
            writer.hand_off()  # a writer process writes the flight's end while this evaluates
        evaluation = evaluate(runner, scene if simulated else None)
        clearance_m: float | None = None
        clearance_building = ""
        if backend.builtin or simulated:  # the built-in vehicle's own, or along the telemetry
            route = [p for _, p in runner.route]
            clearance_m, clearance_building = backend.clearance(route, scene, runner.scene_offset)
        summary = FlightSummary(
            outcome,
            evaluation,
            route_length(runner.route),
            flight_time(runner.route),
            runner.frames,
            path,
            time.monotonic() - wall0,
            link.name,
            vehicle_s,
            clearance_m if clearance_m is None or math.isfinite(clearance_m) else None,
            clearance_building,
            flight_wall_s,
            runner.last_refusal,
            tuple(sorted(link.freshness.dropped_by_type.items())),
            ref.name,
            issubclass(mission_cls, SearchMission),
            tuple(runner.results),
        )
        if recorder is not None:
            recorder.outcome(summary_record(summary))
    return summary


def open_recording(
    stack: ExitStack,
    config: FlyConfig,
    scene: Scene,
    ref: MissionRef,
    has_target: bool,
    flown: list[bool],
) -> tuple[MessageWriter | None, Path | None]:
    """The flight's recording writer and its path (both None with ``no_record``), entered on
    ``stack``: written aside and renamed whole, kept on an error once ``flown`` is set; in a
    process of its own when a core is free (``record_in_process``)."""
    if config.no_record:
        return None, None
    path = config.record or default_recording_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = stack.enter_context(
        atomic_output(
            path,
            inputs=(config.target, config.scene if isinstance(config.scene, str) else None),
            keep_on_error=lambda _exc: bool(flown),
        )
    )
    metadata = describe(config, scene, ref, has_target).to_metadata()
    in_process = config.record_in_process
    if in_process is None:
        in_process = not core_to_spare()
    if in_process:
        from uavtool.recording.writer import RecordingWriter  # noqa: PLC0415 - only to write here

        return stack.enter_context(RecordingWriter(partial, metadata=metadata)), path
    return stack.enter_context(ProcessWriter(partial, metadata=metadata)), path


def summary_record(s: FlightSummary) -> dict[str, object]:
    o = s.outcome
    record: dict[str, object] = {"status": o.status.value, "reason": o.reason}
    if s.searched:
        record |= {
            "visited": list(o.visited),
            "matched_poi": o.matched_poi,
            "match_score": round(o.match_score, 4),
            "model_built": o.model_built,
        }
    record |= {
        "route_length_m": round(s.route_length_m, 1),
        "flight_time_s": round(s.flight_time_s, 1),
        "frames": s.frames,
    }
    for result in s.results:
        record[f"result.{result.tag}"] = result.values
    e = s.evaluation
    if e.matched_building:
        record["matched_building"] = e.matched_building
        record["target_building"] = e.target_building
    if e.model_iou is not None:
        record["model_iou"] = round(e.model_iou, 4)
    if e.tunnel_kept is not None:
        record["tunnel_kept"] = e.tunnel_kept
    if s.clearance_m is not None:
        record["closest_clearance_m"] = round(s.clearance_m, 2)
        record["closest_building"] = s.clearance_building
    if s.last_refusal:
        record["last_refusal"] = s.last_refusal
    if s.stale_dropped:  # only on lossy links: a lockstep flight's record stays as it was
        record["stale_dropped"] = sum(n for _, n in s.stale_dropped)
    return record


def _read_target(path: Path) -> bytes:
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"--target {path}: cannot read: {exc.strerror}") from None
    png_decode(data, where=f"--target {path}")  # fail now, not mid-flight
    return data


def describe(
    config: FlyConfig, scene: Scene, mission: MissionRef, has_target: bool
) -> FlightDescription:
    """What the flight is, as the recording stores it: a function of the flight's inputs alone
    (no paths, ports, dates or speed-up), so that the same inputs give the same file."""
    builtin = config.connect is None and not config.connects
    return FlightDescription(
        mission=mission,
        params=to_dict(config.params),
        scene=scene_to_dict(scene),
        scene_name=scene.name,
        connect=(
            " ".join(config.connects)
            if config.connects
            else CONNECT_BUILTIN
            if builtin
            else str(config.connect)
        ),
        camera=config.camera,
        clock="lockstep" if builtin else "wall",
        scene_origin=_origin_name(config),
        seed=config.seed,
        noise=config.noise,
        wind=config.wind,
        link_outages_s=config.link_outages_s,
        vehicle_params=config.vehicle_params,
        hfov_deg=config.hfov_deg,
        size_px=config.size_px,
        target=("file" if config.target else "scene") if has_target else "none",
        no_gimbal=config.no_gimbal,
        vehicles=config.vehicles,
        offset_line=config.offset_line or (90.0, 10.0),
        homes_m=config.homes_m,
        tool_version=__version__,
    )


def _origin_name(config: FlyConfig) -> str:
    """Which geographic origin the scene was placed at."""
    if config.camera != "sim":
        return "none"
    if config.connect is None:
        return "scene"  # the built-in vehicle boots at the scene's home
    return "vehicle-home" if config.scene_origin == "vehicle" else "scene"


def _abort(
    link: VehicleLink, autopilot: Autopilot, recorder: MissionRecorder | None, why: str
) -> None:
    _return_home(link, autopilot)
    if recorder is not None:
        recorder.note(Level.WARNING, why)
        recorder.outcome({"status": "interrupted", "reason": why})


def _return_home(link: VehicleLink, autopilot: Autopilot) -> None:
    with contextlib.suppress(LinkError, OSError):  # best effort: the link may be what failed
        autopilot.return_home(link)


def _failed(recorder: MissionRecorder | None, exc: Exception) -> None:
    """Say in the recording that the run stopped on an error, so it never passes for a
    mission that ended (the file is kept: the flight did happen)."""
    if recorder is not None:
        with contextlib.suppress(RecordingError, ValueError):  # the recording may be what failed
            recorder.outcome(
                {"status": "failed", "reason": f"the run stopped with an error: {exc}"}
            )


def route_length(route: list[tuple[int, tuple[float, float, float]]]) -> float:
    total = 0.0
    for (_, a), (_, b) in itertools.pairwise(route):
        total += math.dist(a, b)
    return total


def flight_time(route: list[tuple[int, tuple[float, float, float]]]) -> float:
    return (route[-1][0] - route[0][0]) / 1000.0 if len(route) > 1 else 0.0
