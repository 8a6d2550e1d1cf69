"""``uavtool fly``: fly a mission (the built-in search-and-analyze one by default) and record
it."""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import click

from uavtool.checks import MAX_HOME_M, NON_NEGATIVE, POSITIVE, Range, coerce
from uavtool.cli.options import PORT, SEED, Number, Numbers, check_web_ports
from uavtool.cli.spelling import Command, OldSpelling
from uavtool.errors import InputError

if TYPE_CHECKING:
    from uavtool.runner.fly import FlyConfig

Echo = Callable[[str], None]

EXIT_CODES: dict[str, int] = {
    "completed": 0,
    "aborted": 1,
    "pilot-takeover": 1,
    "link-lost": 1,
    "partial": 3,
    "no-match": 4,
    "crashed": 5,
}
"""``uavtool fly``'s exit code for each mission status (2 is bad input, as for every command)."""

_SECONDS = Range(0.0, 86_400.0, lo_open=True)
_WIND = Numbers(",", (("SPEED", Range(0.0, 50.0)), ("DIR", Range(-360.0, 360.0))), example="5,270")
_HOME_M = Numbers(
    ",",
    (("E", Range(-MAX_HOME_M, MAX_HOME_M)), ("N", Range(-MAX_HOME_M, MAX_HOME_M))),
    example="0,20",
)
_OUTAGE = Numbers(":", (("START", NON_NEGATIVE), ("DURATION", POSITIVE)), example="60:10")
# --writer: FlyConfig.record_in_process for each choice
_WRITERS: dict[str, bool | None] = {"auto": None, "process": False, "thread": True}


@click.command(cls=Command, old_spellings=(OldSpelling("--record", "--output", "-o/--output"),))
@click.option(
    "--connect",
    "connects",
    multiple=True,
    metavar="URL",
    help="Vehicle connection: tcp:HOST:PORT, udpin:HOST:PORT, udpout:HOST:PORT or "
    "serial:DEVICE[:BAUD]; repeat it for a fleet (one per vehicle, with a fleet mission). "
    "Default: start the built-in SITL in-process.",
)
@click.option(
    "--scene", default="paper", show_default=True, help="Built-in scene name or scene file."
)
@click.option(
    "--target",
    type=click.Path(path_type=Path),
    default=None,
    help="Picture of the target building from above (PNG). Default: the scene's target, rendered.",
)
@click.option(
    "--camera", default="sim", show_default=True, help="sim, opencv:N (device) or a stream URL."
)
@click.option(
    "--speedup",
    default=None,
    metavar="N|max",
    help="Cap on the built-in vehicle's pace, vehicle seconds per wall second. It never changes "
    "the flight (lockstep). Default: max (as fast as the CPU allows); 1 with --rerun spawn|web.",
)
@click.option(
    "-o",
    "--output",
    "record",
    type=click.Path(path_type=Path),
    default=None,
    help="The recording to write (MCAP).  [default: recordings/<UTC time>.mcap]",
)
@click.option("--no-record", is_flag=True, help="Do not write a recording.")
@click.option(
    "--writer",
    type=click.Choice(_WRITERS),
    default="auto",
    show_default=True,
    help="Where the recording is written: in a process of its own (off the flight's path, "
    "more work in all), on the flight's thread, or auto: in its own process when a core is "
    "free for it. The file is the same either way.",
)
@click.option(
    "--mission",
    "mission",
    default="search",
    show_default=True,
    metavar="NAME|module:Class",
    help="The mission to fly: a registered name (`uavtool missions` lists them) or a "
    "FlightMission subclass as module:Class.",
)
@click.option(
    "--visit-all",
    is_flag=True,
    help="Visit every point of interest, even after a match (the search mission's "
    "mission.visit_all).",
)
@click.option(
    "--param",
    "vehicle_params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Set a vehicle parameter before the flight, by the autopilot's own name "
    "(e.g. WPNAV_SPEED=800 on ArduPilot, MPC_XY_CRUISE=8 on PX4).",
)
@click.option(
    "--set",
    "--mission-param",
    "settings",
    multiple=True,
    metavar="KEY=VALUE",
    help="Set a parameter of the mission (e.g. mission.look_fill=0.6 for the search; "
    "`uavtool missions NAME` lists a mission's).",
)
@click.option("--seed", default=0, show_default=True, type=SEED, help="SITL wind/noise seed.")
@click.option("--noise", is_flag=True, help="Add seeded sensor noise to simulated photos.")
@click.option(
    "--wind",
    default=None,
    type=_WIND,
    metavar="SPEED,DIR",
    help="Built-in SITL wind (0-50 m/s, from deg).",
)
@click.option(
    "--link-outage",
    "outages",
    multiple=True,
    type=_OUTAGE,
    metavar="START:DURATION",
    help="Fault injection (built-in SITL): cut the link for DURATION s at sim time START.",
)
@click.option(
    "--timeout",
    default=30.0,
    show_default=True,
    type=Number(_SECONDS),
    metavar="SECONDS",
    help="How long to wait for the vehicle to connect and report its home (vehicle seconds for "
    "the built-in one).",
)
@click.option(
    "--rerun",
    "rerun_target",
    default=None,
    metavar="spawn|web|FILE.rrd",
    help="Stream the flight to Rerun: live to the native viewer or the web viewer (at real-time "
    "pace), or to a .rrd file (at full speed).",
)
@click.option(
    "--web-port",
    type=PORT,
    default=None,
    metavar="PORT",
    help="With --rerun web: the web viewer's port.  [default: 9090]",
)
@click.option(
    "--grpc-port",
    type=PORT,
    default=None,
    metavar="PORT",
    help="With --rerun web: the port of the server the viewer reads the flight from.  "
    "[default: 9876]",
)
@click.option(
    "--no-gimbal",
    is_flag=True,
    help="The camera is fixed straight down: fly the search only (no gimbal check, no model).",
)
@click.option(
    "--scene-origin",
    type=click.Choice(["vehicle", "scene"]),
    default="vehicle",
    show_default=True,
    help="With --camera sim and --connect: put the scene at the vehicle's home, or keep the "
    "scene's own position (refused, with the SITL --home to use, when the vehicle is far).",
)
@click.option(
    "--vehicles",
    default=1,
    show_default=True,
    type=click.IntRange(1, 16),
    help="Fly N built-in vehicles in one lockstep world with a fleet mission (e.g. --mission "
    "fleet-survey); see docs/fleets.md.",
)
@click.option(
    "--offset-line",
    default="90,10",
    show_default=True,
    metavar="BEARING,SPACING",
    help="With --vehicles: vehicle i's home is i·SPACING m from the scene's home along BEARING "
    "degrees (as ArduPilot's sim_vehicle.py --auto-offset-line); auto: the first line of "
    "homes 10 m apart clear of every building.",
)
@click.option(
    "--home",
    "homes",
    type=_HOME_M,
    multiple=True,
    metavar="E,N",
    help="With --vehicles: a vehicle's home, metres east and north of the scene's home; give it "
    "once per vehicle, in system-id order, in place of --offset-line.",
)
@click.option("-q", "--quiet", is_flag=True, help="Print only the summary.")
def fly(
    connects: tuple[str, ...],
    scene: str,
    target: Path | None,
    camera: str,
    speedup: str | None,
    record: Path | None,
    no_record: bool,
    writer: str,
    mission: str,
    visit_all: bool,
    vehicle_params: tuple[str, ...],
    settings: tuple[str, ...],
    seed: int,
    noise: bool,
    wind: tuple[float, float] | None,
    outages: tuple[tuple[float, float], ...],
    timeout: float,
    rerun_target: str | None,
    web_port: int | None,
    grpc_port: int | None,
    no_gimbal: bool,
    scene_origin: str,
    vehicles: int,
    offset_line: str,
    homes: tuple[tuple[float, float], ...],
    quiet: bool,
) -> None:
    """Fly a mission and record everything to one MCAP file: by default the search mission,
    which finds the target building in the scene, photographs it from three sides and builds
    its 3D model.

    \b
    Exit codes: 0 completed (search: target found, model built), 3 partial (search: target
    found, no model), 4 no match, 5 crashed, 1 aborted / pilot takeover / link lost or the
    mission's code failed, 2 bad input.

    \b
    Examples:
      uavtool fly                                  # built-in SITL, scene 'paper'
      uavtool fly --visit-all --scene blocked-front
      uavtool fly --connect tcp:127.0.0.1:5760     # ArduPilot SITL (sim_vehicle.py)
      uavtool fly --connect tcp:127.0.0.1:5760 --no-gimbal   # a camera fixed down
      uavtool fly --connect udpin:0.0.0.0:14540    # PX4 SITL (its API link)
      uavtool fly --mission orbit --set orbit.step_deg=30   # another mission
      uavtool fly --vehicles 3 --mission fleet-search      # a fleet of built-in vehicles
      uavtool fly --mission fleet-search --connect tcp:127.0.0.1:5760 --connect tcp:127.0.0.1:5770
    """
    from uavtool.mission.params import parse_settings, valid_keys, with_overrides
    from uavtool.plugins import resolve
    from uavtool.runner.fly import FlyConfig
    from uavtool.runner.fly import fly as fly_mission
    from uavtool.runner.params import parse_param
    from uavtool.runner.summary import format_progress, format_summary

    if record is not None and no_record:
        raise InputError("-o/--output and --no-record exclude each other")
    if no_record and writer != "auto":
        raise InputError(f"--writer {writer}: there is no recording to write (--no-record)")
    rerun_target = _rerun_target(rerun_target)
    ports = {"--web-port": web_port, "--grpc-port": grpc_port}
    check_web_ports(ports, web=rerun_target == "web", needs="--rerun web")
    mission_cls, _ = resolve(mission)
    overrides = parse_settings(settings)
    if visit_all:
        if "mission.visit_all" not in valid_keys(mission_cls.params_type):
            raise InputError(f"--visit-all: the mission {mission!r} has no mission.visit_all")
        overrides["mission.visit_all"] = "true"
    params = with_overrides(mission_cls.params_type(), overrides)
    connect = connects[0] if len(connects) == 1 else None
    config = FlyConfig(
        mission=mission,
        connect=connect,
        connects=connects if len(connects) > 1 else (),
        scene=scene,
        target=target,
        camera=camera,
        speedup=_speedup(speedup, live=rerun_target in _LIVE_VIEWERS),
        record=record,
        no_record=no_record,
        record_in_process=_WRITERS[writer],
        params=params,
        vehicle_params=tuple(parse_param(p) for p in vehicle_params),
        seed=seed,
        noise=noise,
        wind=wind if wind is not None else (0.0, 0.0),
        link_outages_s=outages,
        connect_timeout_s=timeout,
        rerun=rerun_target,
        rerun_web_port=web_port,
        rerun_grpc_port=grpc_port,
        no_gimbal=no_gimbal,
        scene_origin=scene_origin,
    )

    def echo(text: str) -> None:
        if not quiet:
            click.echo(text)

    if len(connects) > 1:
        if vehicles not in (1, len(connects)):
            raise InputError(
                f"--vehicles {vehicles} with {len(connects)} --connect: one --connect per vehicle"
            )
        vehicles = len(connects)
    if homes and vehicles == 1:
        raise InputError("--home places a fleet's vehicles: give --vehicles N and N homes")
    if homes and _given("offset_line"):
        raise InputError("--home and --offset-line both place the vehicles: give one of them")
    if vehicles > 1:
        _fly_fleet(config, vehicles, offset_line, homes, echo)
    summary = fly_mission(
        config,
        progress=lambda text, t: echo(format_progress(text, t)),
        status=lambda text: echo(f"uavtool fly: {text}"),
        vehicle_says=lambda text: echo(f"uavtool fly: {text}"),
    )
    click.echo(format_summary(summary))
    sys.exit(EXIT_CODES[summary.outcome.status.value])


_LIVE_VIEWERS = ("spawn", "web")


def _given(name: str) -> bool:
    """Whether the option ``name`` was given on the command line (not its default)."""
    source = click.get_current_context().get_parameter_source(name)
    return source is not None and source is not click.core.ParameterSource.DEFAULT


def _fly_fleet(
    config: FlyConfig,
    vehicles: int,
    offset_line: str,
    homes_m: tuple[tuple[float, float], ...],
    echo: Echo,
) -> NoReturn:
    from uavtool.runner.fleet import fly_fleet
    from uavtool.runner.summary import format_fleet_summary, format_progress
    from uavtool.sitl.fleet import parse_offset_line

    line = None if offset_line.strip() == "auto" else parse_offset_line(offset_line)
    config = dataclasses.replace(
        config,
        vehicles=vehicles,
        offset_line=None if line is None else (line.bearing_deg, line.spacing_m),
        homes_m=homes_m,
    )
    summary = fly_fleet(
        config,
        progress=lambda sysid, text, t: echo(f"v{sysid} {format_progress(text, t)}"),
        status=lambda text: echo(f"uavtool fly: {text}"),
    )
    click.echo(format_fleet_summary(summary))
    sys.exit(EXIT_CODES[summary.status.value])


def _rerun_target(text: str | None) -> str | None:
    """``spawn``, ``web`` or a ``.rrd`` file; a typo is an error, not a file of that name."""
    if text is None or text in _LIVE_VIEWERS or text.lower().endswith(".rrd"):
        return text
    raise click.BadParameter(
        f"{text!r}: expected spawn, web or a file ending in .rrd", param_hint="--rerun"
    )


def _speedup(text: str | None, *, live: bool) -> float | None:
    """``max`` → None (no cap); a positive number → that cap. Watching live defaults to 1."""
    if text is None:
        return 1.0 if live else None
    if text.strip().lower() == "max":
        return None
    try:
        speedup: float = coerce(text, float, name="--speedup", bounds=POSITIVE)
    except InputError:
        raise InputError(f"--speedup={text}: expected a positive number or 'max'") from None
    return speedup
