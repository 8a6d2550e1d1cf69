"""``uavtool fly --vehicles N`` (built-in vehicles in one lockstep world) and ``fly --connect
URL --connect URL …`` (external vehicles on the wall clock): a fleet flown by one fleet mission
(:class:`~uavtool.mission.fleet.FleetMember`, one member per vehicle), into one recording.

Each vehicle has its own link, camera and :class:`Runner`, exactly as one vehicle has; the
world (:mod:`uavtool.runner.fleet_worlds`) turns every runner in one loop, and the runners
share one step counter, so the members see their observations in one order. In lockstep that
order depends on nothing but the flight's inputs: the fleet's flight is as reproducible as one
vehicle's.
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
from uavtool.errors import InputError
from uavtool.geo import enu_from_geo, geo_from_enu
from uavtool.link import VehicleLink
from uavtool.mission import Level, MissionInputs, Outcome, Status, Telemetry
from uavtool.mission.fleet import FleetMember
from uavtool.mission.outputs import Result
from uavtool.plugins import create_fleet, resolve
from uavtool.recording.fleet import CREW_METADATA, VehicleWriter
from uavtool.recording.topics import TARGET
from uavtool.recording.values import CompressedImage
from uavtool.runner.backends import ExternalBackend, builtin_sitl_config
from uavtool.runner.camera import open_camera
from uavtool.runner.evaluate import Evaluation, evaluate
from uavtool.runner.fleet_worlds import BuiltinWorld, ExternalWorld
from uavtool.runner.fly import (
    FlyConfig,
    flight_time,
    open_recording,
    prepare,
    route_length,
)
from uavtool.runner.params import set_vehicle_params
from uavtool.runner.preflight import check_fence, check_gimbal, check_home
from uavtool.runner.record import MissionRecorder
from uavtool.runner.runner import Progress, Runner
from uavtool.world import Scene

if TYPE_CHECKING:
    from uavtool.link import Transport
    from uavtool.mission.base import Envelope
    from uavtool.recording.protocol import MessageWriter
    from uavtool.sitl.config import SitlConfig

MAX_VEHICLES = 16
"""The most vehicles ``fly --vehicles`` flies in one world."""
AUTO_SPACING_M = 10.0
"""The spacing of an automatic offset line (``--offset-line auto``): ArduPilot's default."""


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
    """The fleet's, as its mission's crew judges it from the members' (``Crew.outcome``)."""
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
    lockstep: bool = True
    """Built-in vehicles in lockstep (times are vehicle time), else the wall clock."""

    @property
    def flight_wall_s(self) -> float:
        return self.wall_time_s


def fly_fleet(
    config: FlyConfig,
    *,
    progress: Callable[[int, str, Telemetry | None], None] | None = None,
    status: Callable[[str], None] | None = None,
) -> FleetSummary:
    """Fly a fleet with the fleet mission ``config.mission`` and record it in one file: the
    vehicles of ``config.connects`` (one connection each, on the wall clock), or else
    ``config.vehicles`` built-in vehicles in lockstep, homes on ``config.offset_line`` from
    the scene's home. ``progress`` hears each member's events (with its sysid and latest
    telemetry)."""
    from uavtool.sitl.fleet import (  # noqa: PLC0415
        clear_line,
        vehicle_seed,
    )
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    say = status or (lambda _text: None)
    wall0 = time.monotonic()
    if config.connects:
        config = dataclasses.replace(config, vehicles=len(config.connects), offset_line=None)
    vehicles, line = config.vehicles, config.offset_line
    if not 1 <= vehicles <= MAX_VEHICLES:
        raise InputError(f"--vehicles {vehicles}: a fleet flies 1 to {MAX_VEHICLES} vehicles")
    if config.connect is not None:
        raise InputError(
            f"--vehicles {vehicles} with one --connect: give one --connect URL per vehicle"
        )
    if config.rerun is not None:
        raise InputError(
            "--rerun with a fleet: the live view shows one vehicle so far; record the fleet and "
            "open the file in Foxglove or Lichtblick"
        )
    if config.camera != "sim":
        raise InputError(
            f"--camera {config.camera} with a fleet: each vehicle needs a camera of its own, and "
            "a fleet flies with the simulated camera only so far"
        )
    mission_cls, ref = resolve(config.mission)
    if not issubclass(mission_cls, FleetMember):
        raise InputError(
            f"--vehicles {vehicles}: mission {ref.name!r} flies one vehicle; a fleet flies a "
            "fleet mission (e.g. --mission fleet-survey; see docs/fleets.md)"
        )
    setup = prepare(config, mission_cls)
    config, scene, intrinsics = setup.config, setup.scene, setup.intrinsics
    params, target_png, target_rgb = config.params, setup.target_png, setup.target_rgb
    fleet_params = getattr(params, mission_cls.fleet_group)
    if config.homes_m:
        line = _given_homes(config, scene, fleet_params.separation_m)
    elif line is None and not config.connects:  # the first line of homes clear of buildings
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
    spacing = line[1] if line is not None else math.inf
    if line is not None and not config.homes_m and spacing < fleet_params.separation_m:
        raise InputError(
            f"--offset-line {line[0]:g},{spacing:g}: the homes stand closer than the fleet's "
            f"separation ({fleet_params.separation_m:g} m); space them wider"
        )
    external = bool(config.connects)
    world: BuiltinWorld | ExternalWorld
    if external:
        world = ExternalWorld(config.connects, timeout_s=config.connect_timeout_s, say=say)
        say(f"{vehicles} vehicles on {', '.join(config.connects)}, scene {scene.name!r}")
    else:
        assert line is not None
        world = BuiltinWorld(_builtin_configs(config, scene, line), speedup=config.speedup)
        pace = "as fast as it can" if config.speedup is None else f"≤ {config.speedup:g}x"
        say(f"{vehicles} built-in vehicles in lockstep ({pace}), scene {scene.name!r}")
    with ExitStack() as stack:
        stack.callback(world.close)
        flown: list[bool] = []  # set once the mission starts: from then on the file is kept
        writer, path = open_recording(stack, config, scene, ref, target_png is not None, flown)
        if writer is not None and target_png is not None:
            picture = CompressedImage(target_png, frame_id="target")
            writer.write(TARGET, picture, log_time_ns=world.clock_ns())
        envelope = mission_cls.envelope(params, intrinsics)
        links = [_connect(t, world, writer, config, envelope, say) for t in world.transports]
        sysids = [link.target_system for link in links]
        if len(set(sysids)) != len(sysids):
            raise InputError(
                f"the vehicles answer with system ids {sysids}: a fleet needs one each "
                "(set MAV_SYSID, SYSID_THISMAV before ArduPilot 4.7, or MAV_SYS_ID on PX4)"
            )
        homes = [link.state.home for link in links]
        first = homes[0]
        assert first is not None
        homes_en = tuple(enu_from_geo(first, h)[:2] for h in homes if h is not None)
        _check_apart(homes_en, sysids, fleet_params.separation_m)
        origin = scene.home  # the fleet flies with the simulated camera only (checked above)
        if external:
            origin = ExternalBackend(world.transports[0], config.scene_origin).scene_origin(
                scene, first, say
            )
        if writer is not None:  # an input of the mission: replay builds the crew from it
            writer.add_metadata(
                CREW_METADATA, {"homes_en_m": json.dumps([list(h) for h in homes_en])}
            )
        members = create_fleet(mission_cls, params, MissionInputs(target_rgb=target_rgb), homes_en)
        steps = itertools.count(1)  # one order for every member's observations
        runners = []
        for i, (link, member) in enumerate(zip(links, members, strict=True)):
            camera = open_camera(
                config.camera,
                scene=scene,
                intrinsics=intrinsics,
                noise_seed=vehicle_seed(config.seed, i) if config.noise else None,
            )
            stack.callback(camera.close)
            recorder = None
            if writer is not None:
                recorder = MissionRecorder(
                    VehicleWriter(writer, link.target_system), clock_ns=world.clock_ns
                )
                recorder.home = link.state.home
                said = f"connected to sysid {link.target_system} on {link.name}"
                recorder.note(Level.INFO, said)
            runners.append(
                Runner(
                    link,
                    camera,
                    member,
                    recorder=recorder,
                    scene_origin=origin,
                    true_pose=world.true_pose(i),
                    progress=_told(progress, link.target_system),
                    autopilot=for_vehicle(link.state.heartbeat),
                    config=world.runner_config,
                    steps=steps,
                )
            )
        vehicle0 = world.clock()
        flown.append(True)
        outcomes = world.run(runners)
        vehicle_s = world.clock() - vehicle0
        summaries = tuple(
            VehicleSummary(
                link.target_system,
                outcome,
                route_length(runner.route),
                flight_time(runner.route),
                runner.frames,
                world.clearance(i, runner, scene),
                tuple(runner.results),
            )
            for i, (link, runner, outcome) in enumerate(zip(links, runners, outcomes, strict=True))
        )
        fleet_status, reason = members[0].crew.outcome(list(outcomes))
        distance_m, pair = world.approach()
        summary = FleetSummary(
            fleet_status,
            reason,
            summaries,
            distance_m,
            pair,
            fleet_params.separation_m,
            vehicle_s,
            time.monotonic() - wall0,
            ref.name,
            path,
            evaluate(runners[0], scene),
            lockstep=not external,
        )
        for s, recorder in zip(summaries, (r.recorder for r in runners), strict=True):
            if recorder is not None:
                recorder.outcome(_vehicle_record(s))
        if writer is not None:
            writer.add_metadata("outcome", fleet_record(summary))
    return summary


def _builtin_configs(
    config: FlyConfig, scene: Scene, line: tuple[float, float]
) -> tuple[SitlConfig, ...]:
    """The built-in vehicles: booted as ``fly`` boots one, homes on the offset line."""
    from uavtool.sitl.fleet import OffsetLine, fleet_configs, line_homes  # noqa: PLC0415
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    base = builtin_sitl_config(config, scene, obstacles=())
    if config.homes_m:
        homes = tuple(geo_from_enu(scene.home, e, n, 0.0) for e, n in config.homes_m)
    else:
        homes = line_homes(scene.home, config.vehicles, OffsetLine(*line))
    return fleet_configs(base, homes, obstacles_for=lambda h: scene_obstacles(scene, home=h))


def _given_homes(
    config: FlyConfig, scene: Scene, separation_m: float
) -> tuple[float, float] | None:
    """Check the homes given one by one (``--home E,N``): one per built-in vehicle, each clear
    of every building by the fleet's separation (the vehicles' spacing is checked once they
    report their homes). Returns the offset line, which they replace."""
    from uavtool.sitl.obstacles import ObstacleField  # noqa: PLC0415
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    homes = config.homes_m
    if config.connects:
        raise InputError(
            "--home with --connect: external vehicles report their own homes; set them on the "
            "vehicles (e.g. ArduPilot SITL's --home)"
        )
    if len(homes) != config.vehicles:
        raise InputError(
            f"--home given {len(homes)} times for {config.vehicles} vehicles: give it once per "
            "vehicle, in system-id order"
        )
    for k, (east, north) in enumerate(homes, start=1):
        here = geo_from_enu(scene.home, east, north, 0.0)
        gap_m = ObstacleField(scene_obstacles(scene, home=here)).nearest(0.0, 0.0, 0.0)[0]
        if gap_m < separation_m:
            raise InputError(
                f"--home {east:g},{north:g} (vehicle {k}): {max(gap_m, 0.0):.1f} m from a "
                f"building, closer than the fleet's separation ({separation_m:g} m); move it"
            )
    return config.offset_line or (90.0, 10.0)


def _connect(
    transport: Transport,
    world: BuiltinWorld | ExternalWorld,
    writer: MessageWriter | None,
    config: FlyConfig,
    envelope: Envelope,
    say: Callable[[str], None],
) -> VehicleLink:
    """One vehicle's link, its every frame recorded on the shared MAVLink channels, checked
    on the ground as ``fly`` checks one vehicle."""
    link = VehicleLink(
        transport,
        tap=None if writer is None else writer.mavlink_tap(world.clock_ns),
        clock=world.clock,
        announce=world.announce,
    )
    link.wait_vehicle(config.connect_timeout_s)
    autopilot = for_vehicle(link.state.heartbeat)
    learnt = autopilot.prepare(link)
    if learnt:
        say(learnt)
    if config.vehicle_params:
        set_vehicle_params(link, config.vehicle_params, autopilot)
    check_home(link)
    if not config.no_gimbal:
        check_gimbal(link, autopilot)
    check_fence(link, autopilot, envelope)
    home = link.state.home
    assert home is not None
    say(f"vehicle {link.target_system} on {link.name}, home {home.lat_deg:.6f},{home.lon_deg:.6f}")
    return link


def _check_apart(
    homes_en: tuple[tuple[float, float], ...], sysids: list[int], separation_m: float
) -> None:
    for i, a in enumerate(homes_en):
        for j in range(i):
            apart = math.dist(a, homes_en[j])
            if apart < separation_m:
                raise InputError(
                    f"vehicles {sysids[j]} and {sysids[i]} stand {apart:.1f} m apart, less than "
                    f"the fleet's separation ({separation_m:g} m): give them homes farther apart"
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


def _told(
    progress: Callable[[int, str, Telemetry | None], None] | None, sysid: int
) -> Progress | None:
    if progress is None:
        return None
    return lambda text, t: progress(sysid, text, t)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None
