"""``uavtool fly --vehicles N``: a fleet of built-in vehicles in one lockstep world, flown by
one fleet mission (:class:`~uavtool.mission.fleet.FleetMember`, one member per vehicle).

Each vehicle has its own link, camera and :class:`Runner`, exactly as one vehicle has; one loop
turns every runner (reading what its vehicle said, feeding its member) and steps the world only
when no runner has anything left to do. So the members see their observations in one order
that depends on nothing but the flight's inputs, and the fleet's flight is as reproducible as
one vehicle's.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from uavtool.autopilot import for_vehicle
from uavtool.camera import Intrinsics
from uavtool.errors import InputError
from uavtool.geo import enu_from_geo
from uavtool.images import png_decode
from uavtool.link import VehicleLink
from uavtool.mission import Level, MissionInputs, Outcome, Status, Telemetry
from uavtool.mission.fleet import FleetMember
from uavtool.mission.outputs import Result
from uavtool.mission.params import with_overrides
from uavtool.plugins import MissionRef, create_fleet, resolve
from uavtool.recording.cores import core_to_spare
from uavtool.recording.files import atomic_output
from uavtool.recording.fleet import CREW_METADATA, VehicleWriter
from uavtool.recording.process import ProcessWriter
from uavtool.recording.topics import TARGET
from uavtool.recording.values import CompressedImage
from uavtool.runner.backends import BOOT_ONLY_PARAMS
from uavtool.runner.camera import open_camera
from uavtool.runner.evaluate import Evaluation, evaluate
from uavtool.runner.fly import (
    FlyConfig,
    _flight_time,
    _read_target,
    _route_length,
    default_recording_path,
    describe,
    target_picture,
)
from uavtool.runner.params import set_vehicle_params
from uavtool.runner.preflight import check_fence, check_gimbal, check_home
from uavtool.runner.record import MissionRecorder
from uavtool.runner.runner import Progress, Runner
from uavtool.world import Scene, load_scene

if TYPE_CHECKING:
    from uavtool.camera import CameraPose
    from uavtool.recording.protocol import MessageWriter
    from uavtool.sitl.fleet import Fleet
    from uavtool.sitl.lockstep import FleetLockstep

MAX_VEHICLES = 16
AUTO_SPACING_M = 10.0
"""The spacing of an automatic offset line (``--offset-line auto``): ArduPilot's default."""
"""The most vehicles ``fly --vehicles`` flies in one world."""


@dataclass(frozen=True, slots=True)
class VehicleSummary:
    sysid: int
    outcome: Outcome
    route_length_m: float
    flight_time_s: float
    frames: int
    clearance_m: float | None
    """Least gap between its body and a building while airborne (None without buildings)."""
    results: tuple[Result, ...]


@dataclass(frozen=True, slots=True)
class FleetSummary:
    status: Status
    """The fleet's: crashed if any vehicle crashed, else the worst of the members' statuses
    (completed only when every member completed)."""
    reason: str
    vehicles: tuple[VehicleSummary, ...]
    closest_approach_m: float
    """Least distance between two vehicles' positions while either was off the ground."""
    closest_pair: tuple[int, int]
    separation_m: float
    vehicle_time_s: float
    """Vehicle (world) time from the first observation to the last member's end."""
    wall_time_s: float
    mission: str
    recording: Path | None = None
    evaluation: Evaluation | None = None
    """The first vehicle's mission judged against the scene (a search: the building it
    matched and the model's overlap with it)."""

    @property
    def flight_wall_s(self) -> float:
        return self.wall_time_s


def fly_fleet(
    config: FlyConfig,
    *,
    progress: Callable[[int, str, Telemetry | None], None] | None = None,
    status: Callable[[str], None] | None = None,
) -> FleetSummary:
    """Fly ``config.vehicles`` built-in vehicles, homes on ``config.offset_line`` from the
    scene's home, with the fleet mission ``config.mission``, and record them in one file.
    ``progress`` hears each member's events (with its sysid and latest telemetry)."""
    from uavtool.sitl import SitlConfig  # noqa: PLC0415 - a real vehicle needs no simulator
    from uavtool.sitl.fleet import (  # noqa: PLC0415
        OffsetLine,
        clear_line,
        fleet_configs,
        line_homes,
        vehicle_seed,
    )
    from uavtool.sitl.lockstep import SIM_EPOCH_UNIX_S, FleetLockstep  # noqa: PLC0415
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    say = status or (lambda _text: None)
    wall0 = time.monotonic()
    vehicles, line = config.vehicles, config.offset_line
    if not 1 <= vehicles <= MAX_VEHICLES:
        raise InputError(f"--vehicles {vehicles}: a fleet flies 1 to {MAX_VEHICLES} vehicles")
    if config.connect is not None:
        raise InputError(
            "--vehicles with --connect: fleets of external vehicles are not supported yet "
            "(fly the built-in vehicles, or one external vehicle)"
        )
    mission_cls, ref = resolve(config.mission)
    if not issubclass(mission_cls, FleetMember):
        raise InputError(
            f"--vehicles {vehicles}: mission {ref.name!r} flies one vehicle; a fleet flies a "
            "fleet mission (e.g. --mission fleet-survey; see docs/fleets.md)"
        )
    params = config.params if config.params is not None else mission_cls.params_type()
    if config.no_gimbal:
        params = with_overrides(params, {f"{mission_cls.flight_group}.gimbal": False})
    config = dataclasses.replace(config, params=params)
    scene = config.scene if isinstance(config.scene, Scene) else load_scene(config.scene)
    w, h = config.size_px
    intrinsics = Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=config.hfov_deg)
    target_png = None
    if config.target:
        target_png = _read_target(config.target)
    elif mission_cls.needs_target:
        target_png = target_picture(scene, intrinsics)
    target_rgb = None if target_png is None else png_decode(target_png, where="target")
    fleet_params = getattr(params, mission_cls.fleet_group)
    if line is None:  # automatic: the first line whose homes are clear of every building
        found = clear_line(
            scene.home,
            vehicles,
            lambda h: scene_obstacles(scene, home=h),
            spacing_m=AUTO_SPACING_M,
            clear_m=fleet_params.separation_m,
        )
        if found is None:
            raise InputError(
                f"--offset-line auto: no line of {vehicles} homes {AUTO_SPACING_M:g} m apart "
                f"keeps {fleet_params.separation_m:g} m from every building; give one "
                "(--offset-line BEARING,SPACING)"
            )
        line = (found.bearing_deg, found.spacing_m)
        say(f"homes on the offset line {found} (automatic)")
        config = dataclasses.replace(config, offset_line=line)
    spacing = line[1]
    if spacing < fleet_params.separation_m:
        raise InputError(
            f"--offset-line {line[0]:g},{spacing:g}: the homes stand closer than the fleet's "
            f"separation ({fleet_params.separation_m:g} m); space them wider"
        )
    mount = 0.0 if config.no_gimbal else 1.0
    boot: tuple[tuple[str, float], ...] = (("MNT1_TYPE", mount), ("WP_YAW_BEHAVIOR", 0.0))
    boot += tuple((n, v) for n, v in config.vehicle_params if n in BOOT_ONLY_PARAMS)
    base = SitlConfig(
        params=boot,
        endpoints=(),
        home=scene.home,
        home_heading_deg=scene.home_heading_deg,
        seed=config.seed,
        wind_speed_ms=config.wind[0],
        wind_dir_deg=config.wind[1],
        link_outages_s=config.link_outages_s,
        start_unix_us=SIM_EPOCH_UNIX_S * 1_000_000,
    )
    homes = line_homes(scene.home, vehicles, OffsetLine(*line))
    configs = fleet_configs(base, homes, obstacles_for=lambda h: scene_obstacles(scene, home=h))
    with ExitStack() as stack:
        world = FleetLockstep(configs, speedup=config.speedup)
        stack.callback(world.close)
        pace = "as fast as it can" if config.speedup is None else f"≤ {config.speedup:g}x"
        say(f"{vehicles} built-in vehicles in lockstep ({pace}), scene {scene.name!r}")
        flown: list[bool] = []  # set once the mission starts: from then on the file is kept
        writer, path = _open_writer(stack, config, scene, ref, target_png, flown)
        recorders = [
            None
            if writer is None
            else MissionRecorder(
                VehicleWriter(writer, c.sysid + c.instance), clock_ns=world.recording_ns
            )
            for c in configs
        ]
        if writer is not None and target_png is not None:
            picture = CompressedImage(target_png, frame_id="target")
            writer.write(TARGET, picture, log_time_ns=world.recording_ns())
        links, autopilots = [], []
        for transport, recorder in zip(world.members, recorders, strict=True):
            link = VehicleLink(
                transport,
                tap=recorder.mavlink if recorder else None,
                clock=world.clock,
                announce=False,
            )
            link.wait_vehicle(config.connect_timeout_s)
            autopilot = for_vehicle(link.state.heartbeat)
            autopilot.prepare(link)
            if config.vehicle_params:
                set_vehicle_params(link, config.vehicle_params, autopilot)
            check_home(link)
            if not config.no_gimbal:
                check_gimbal(link, autopilot)
            check_fence(link, autopilot, mission_cls.envelope(params, intrinsics))
            home = link.state.home
            assert home is not None
            where = f"{home.lat_deg:.6f},{home.lon_deg:.6f}"
            say(f"vehicle {link.target_system} on {link.name}, home {where}")
            if recorder is not None:
                recorder.home = home
                said = f"connected to sysid {link.target_system} on {link.name}"
                recorder.note(Level.INFO, said)
            links.append(link)
            autopilots.append(autopilot)
        first = links[0].state.home
        assert first is not None
        homes_en = tuple(
            enu_from_geo(first, link.state.home)[:2]  # type: ignore[arg-type]
            for link in links
        )
        if writer is not None:  # an input of the mission: replay builds the crew from it
            writer.add_metadata(
                CREW_METADATA, {"homes_en_m": json.dumps([list(h) for h in homes_en])}
            )
        members = create_fleet(mission_cls, params, MissionInputs(target_rgb=target_rgb), homes_en)
        steps = itertools.count(1)  # one order for every member's observations
        runners = []
        for i, (link, autopilot, member, recorder) in enumerate(
            zip(links, autopilots, members, recorders, strict=True)
        ):
            camera = open_camera(
                config.camera,
                scene=scene,
                intrinsics=intrinsics,
                noise_seed=vehicle_seed(config.seed, i) if config.noise else None,
            )
            stack.callback(camera.close)
            runners.append(
                Runner(
                    link,
                    camera,
                    member,
                    recorder=recorder,
                    scene_origin=scene.home,
                    true_pose=_pose_of(world, i),
                    progress=_told(progress, link.target_system),
                    autopilot=autopilot,
                    steps=steps,
                )
            )
        vehicle0 = world.clock()
        flown.append(True)
        outcomes = _run(world, runners)
        vehicle_s = world.clock() - vehicle0
        fleet = world.fleet
        summaries = tuple(
            VehicleSummary(
                link.target_system,
                outcome,
                _route_length(runner.route),
                _flight_time(runner.route),
                runner.frames,
                _finite(vehicle.closest_clearance_m),
                tuple(runner.results),
            )
            for link, runner, outcome, vehicle in zip(
                links, runners, outcomes, fleet.vehicles, strict=True
            )
        )
        fleet_status, reason = members[0].crew.outcome(list(outcomes))
        summary = dataclasses.replace(
            _summarise(
                summaries, fleet_status, reason, fleet, fleet_params.separation_m, vehicle_s,
                wall0, ref.name, path,
            ),
            evaluation=evaluate(runners[0], scene),
        )  # fmt: skip
        for s, recorder in zip(summaries, recorders, strict=True):
            if recorder is not None:
                recorder.outcome(_vehicle_record(s))
        if writer is not None:
            writer.add_metadata("outcome", fleet_record(summary))
    return summary


def _summarise(
    summaries: tuple[VehicleSummary, ...],
    status: Status,
    reason: str,
    fleet: Fleet,
    separation_m: float,
    vehicle_s: float,
    wall0: float,
    mission: str,
    path: Path | None,
) -> FleetSummary:
    approach = fleet.approach
    return FleetSummary(
        status,
        reason,
        summaries,
        approach.distance_m,
        approach.sysids,
        separation_m,
        vehicle_s,
        time.monotonic() - wall0,
        mission,
        path,
    )


def fleet_record(s: FleetSummary) -> dict[str, str]:
    """The fleet's outcome as the recording's ``outcome`` metadata."""
    record = {
        "status": s.status.value,
        "reason": s.reason,
        "vehicles": str(len(s.vehicles)),
        "flight_time_s": f"{s.vehicle_time_s:.1f}",
        "separation_m": f"{s.separation_m:g}",
    }
    if math.isfinite(s.closest_approach_m):
        record["closest_approach_m"] = f"{s.closest_approach_m:.2f}"
        record["closest_pair"] = json.dumps(list(s.closest_pair))
    e = s.evaluation
    if e is not None and e.matched_building:
        record["matched_building"] = e.matched_building
        record["target_building"] = e.target_building
    if e is not None and e.model_iou is not None:
        record["model_iou"] = f"{e.model_iou:.4f}"
    return record


def _vehicle_record(v: VehicleSummary) -> dict[str, object]:
    record: dict[str, object] = {
        "status": v.outcome.status.value,
        "reason": v.outcome.reason,
        "route_length_m": round(v.route_length_m, 1),
        "flight_time_s": round(v.flight_time_s, 1),
        "frames": v.frames,
    }
    for result in v.results:
        record[f"result.{result.tag}"] = result.values
    if v.clearance_m is not None:
        record["closest_clearance_m"] = round(v.clearance_m, 2)
    return record


def _open_writer(
    stack: ExitStack,
    config: FlyConfig,
    scene: Scene,
    ref: MissionRef,
    target_png: bytes | None,
    flown: list[bool],
) -> tuple[MessageWriter | None, Path | None]:
    """The fleet's recording, written whole or not at all (as one vehicle's)."""
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
    metadata = describe(config, scene, ref, target_png is not None).to_metadata()
    in_process = config.record_in_process
    if in_process is None:
        in_process = not core_to_spare()
    if in_process:
        from uavtool.recording.writer import RecordingWriter  # noqa: PLC0415

        return stack.enter_context(RecordingWriter(partial, metadata=metadata)), path
    return stack.enter_context(ProcessWriter(partial, metadata=metadata)), path


def _run(world: FleetLockstep, runners: list[Runner]) -> list[Outcome]:
    """Turn every runner until each mission is done; step the world when none has anything
    left to read or feed."""
    for runner in runners:
        runner.begin()
    done = [False] * len(runners)
    poll_s = runners[0].config.poll_s
    while True:
        for i, runner in enumerate(runners):
            if not done[i] and runner.turn(0.0):
                done[i] = True
                world.members[i].close()  # what it says from now on is nobody's
        if all(done):
            return [r.finish() for r in runners]
        if any(r.busy for i, r in enumerate(runners) if not done[i]):
            continue
        world.step_until_said(poll_s)


def _pose_of(world: FleetLockstep, index: int) -> Callable[[], CameraPose]:
    return lambda: world.camera_pose(index)


def _told(
    progress: Callable[[int, str, Telemetry | None], None] | None, sysid: int
) -> Progress | None:
    if progress is None:
        return None
    return lambda text, t: progress(sysid, text, t)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None
