"""``uavtool sitl``: run the built-in MAVLink vehicle."""

from __future__ import annotations

import dataclasses
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import click

if TYPE_CHECKING:
    from uavtool.sitl.fleet import Fleet, OffsetLine


class _Stopped(KeyboardInterrupt):
    """SIGTERM: stop as cleanly as on Ctrl-C."""


def _interrupt(_signum: int, _frame: object) -> None:
    raise _Stopped


@click.command()
@click.option(
    "--endpoint",
    "endpoints",
    multiple=True,
    metavar="KIND:HOST:PORT",
    help="Where to serve MAVLink (repeatable): tcpin:, udpin:, udpout:, tcp:. "
    "Default: tcpin:127.0.0.1:5760 and udpout:127.0.0.1:14550.",
)
@click.option(
    "--home",
    "homes",
    multiple=True,
    metavar="LAT,LON,ALT,HDG",
    help="Home position and heading. With --vehicles N: once (the first vehicle's; the others "
    "stand on --offset-line) or N times, one per vehicle.",
)
@click.option(
    "--vehicles",
    default=1,
    show_default=True,
    type=click.IntRange(1, 64),
    help="Serve N vehicles in one world and clock: vehicle i is instance --instance+i (ports "
    "+10·i, sysid +i); vehicles that touch both crash.",
)
@click.option(
    "--offset-line",
    default="90,10",
    show_default=True,
    metavar="BEARING,SPACING",
    help="With --vehicles: vehicle i stands i·SPACING m from the first along BEARING degrees "
    "(as ArduPilot's sim_vehicle.py --auto-offset-line).",
)
@click.option(
    "--scene",
    default=None,
    metavar="NAME|FILE",
    help="Fly among a scene's buildings (built-in name or scene file): touching one is a crash. "
    "Home and heading default to the scene's.",
)
@click.option(
    "--speedup", default=1.0, show_default=True, type=float, help="Sim time runs N× wall time."
)
@click.option("--sysid", default=1, show_default=True, type=int, help="MAVLink system id.")
@click.option(
    "--instance", default=0, show_default=True, type=int, help="Vehicle N: ports +10·N, sysid +N."
)
@click.option(
    "--wind", default=None, metavar="SPEED,DIR", help="Wind in m/s, blowing from DIR degrees."
)
@click.option(
    "--seed", default=0, show_default=True, type=int, help="Seed for wind gusts and sensor noise."
)
@click.option(
    "--signing-key", default=None, metavar="HEX", help="MAVLink 2 signing key (64 hex digits)."
)
@click.option(
    "--params",
    "params_file",
    default=None,
    type=click.Path(path_type=Path),
    help="Parameter file (NAME VALUE per line, as MAVProxy saves).",
)
@click.option(
    "--param",
    "param_texts",
    multiple=True,
    metavar="NAME=VALUE",
    help="Set a vehicle parameter at start (repeatable; after --params), e.g. RTL_ALT=3000.",
)
@click.option(
    "--duration",
    default=None,
    type=float,
    metavar="SECONDS",
    help="Stop after this many simulated seconds.",
)
@click.option(
    "--link-outage",
    "outages",
    multiple=True,
    metavar="START:DURATION",
    help="Fault injection: cut every link for DURATION s from sim time START (repeatable).",
)
def sitl(
    endpoints: tuple[str, ...],
    homes: tuple[str, ...],
    vehicles: int,
    offset_line: str,
    scene: str | None,
    speedup: float,
    sysid: int,
    instance: int,
    wind: str | None,
    seed: int,
    signing_key: str | None,
    params_file: Path | None,
    param_texts: tuple[str, ...],
    duration: float | None,
    outages: tuple[str, ...],
) -> None:
    """Run the built-in ArduCopter-like vehicle as a MAVLink endpoint.

    Connect MAVProxy, QGroundControl, MAVSDK or your own pymavlink code to it.

    \b
    Example:
      uavtool sitl --speedup 5 --scene paper
      mavproxy.py --master tcp:127.0.0.1:5760
      uavtool sitl --vehicles 3 --scene paper    # tcp 5760, 5770, 5780; sysid 1, 2, 3
    """
    from uavtool.errors import InputError
    from uavtool.geo import GeoPoint
    from uavtool.sitl import Prism, Sitl, SitlConfig, parse_home, parse_signing_key
    from uavtool.sitl.config import (
        ARMING_SETTLE_S,
        DEFAULT_ENDPOINTS,
        parse_duration,
        parse_outage,
        parse_param,
        parse_wind,
    )
    from uavtool.sitl.fleet import Fleet, fleet_configs, line_homes, parse_offset_line
    from uavtool.sitl.mount import SERVO_ROLL_TRIM_DEG
    from uavtool.sitl.params import load_param_file

    kwargs: dict[str, object] = {}
    given = [parse_home(text) for text in homes]
    if len(given) not in (0, 1, vehicles):
        raise InputError(
            f"--home given {len(given)} times for {vehicles} vehicles: give it once (the first "
            "vehicle's; the others stand on --offset-line) or once per vehicle"
        )
    line = parse_offset_line(offset_line)
    home_point = None
    if given:
        home_point, kwargs["home_heading_deg"] = given[0]
        kwargs["home"] = home_point
    scene_text = ""
    obstacles_for = None
    if scene is not None:
        from uavtool.world import load_scene
        from uavtool.world.obstacles import scene_obstacles

        loaded = load_scene(scene)
        if home_point is None:
            kwargs["home"], kwargs["home_heading_deg"] = loaded.home, loaded.home_heading_deg
        # With --home the buildings stay where the scene puts them on the map.
        kwargs["obstacles"] = obstacles = scene_obstacles(loaded, home=home_point)
        scene_text = f", scene {loaded.name!r} ({len(obstacles)} obstacles)"

        def obstacles_for(home: GeoPoint) -> tuple[Prism, ...]:
            return scene_obstacles(loaded, home=home)

    if wind is not None:
        kwargs["wind_speed_ms"], kwargs["wind_dir_deg"] = parse_wind(wind)
    if signing_key is not None:
        kwargs["signing_key"] = parse_signing_key(signing_key)
    duration = parse_duration(duration)
    params = load_param_file(params_file) if params_file is not None else {}
    params.update(parse_param(text) for text in param_texts)
    kwargs["params"] = tuple(params.items())
    config = SitlConfig(
        endpoints=endpoints or DEFAULT_ENDPOINTS,
        speedup=speedup,
        sysid=sysid,
        instance=instance,
        seed=seed,
        link_outages_s=tuple(parse_outage(text) for text in outages),
        # As ArduCopter's SITL: arming refused while it boots, a servo mount's residual roll.
        arming_settle_s=ARMING_SETTLE_S,
        mount_roll_trim_deg=SERVO_ROLL_TRIM_DEG,
        **kwargs,  # type: ignore[arg-type]
    )
    if vehicles > 1:
        if len(given) == vehicles:
            fleet_homes = [home for home, _ in given]
        else:
            fleet_homes = list(line_homes(config.home, vehicles, line))
        configs = fleet_configs(config, fleet_homes, obstacles_for=obstacles_for)
        if len(given) == vehicles:  # each its own heading too
            configs = tuple(
                dataclasses.replace(c, home_heading_deg=heading)
                for c, (_, heading) in zip(configs, given, strict=True)
            )
        _serve_fleet(Fleet(configs), duration, scene_text, line if len(given) < vehicles else None)
        return
    vehicle = Sitl(config)
    signal.signal(signal.SIGTERM, _interrupt)  # `kill` stops it as cleanly as Ctrl-C
    code = 0
    try:  # from the first line it prints, a stop signal stops it cleanly
        click.echo(
            f"uavtool sitl: vehicle sysid {vehicle.sysid}, speedup {vehicle.speedup:g}x{scene_text}"
        )
        for ep in vehicle.describe_endpoints():
            click.echo(f"  serving MAVLink on {ep}")
        click.echo("  Ctrl-C to stop")
        vehicle.run(duration_s=duration)
    except KeyboardInterrupt as stop:
        # as every command and shell: 128 + the signal (Ctrl-C 130, `kill` 143)
        code = 128 + (signal.SIGTERM if isinstance(stop, _Stopped) else signal.SIGINT)
    finally:
        vehicle.close()
    click.echo(f"uavtool sitl: stopped at sim time {vehicle.now_ns / 1e9:.1f} s")
    if vehicle.crashed:
        click.echo(f"  the vehicle crashed: {vehicle.crash_reason}")
    if code:
        sys.exit(code)


def _serve_fleet(
    fleet: Fleet, duration: float | None, scene_text: str, line: OffsetLine | None
) -> None:
    """Serve a fleet until stopped, and say what became of it."""
    signal.signal(signal.SIGTERM, _interrupt)
    code = 0
    try:
        where = f" on offset line {line}" if line is not None else ""
        click.echo(
            f"uavtool sitl: {len(fleet.vehicles)} vehicles{where}, speedup "
            f"{fleet.speedup:g}x{scene_text}"
        )
        for vehicle in fleet.vehicles:
            home = vehicle.config.home
            endpoints = ", ".join(vehicle.describe_endpoints()) or "no endpoint"
            click.echo(
                f"  vehicle sysid {vehicle.sysid} at {home.lat_deg:.6f},{home.lon_deg:.6f}: "
                f"{endpoints}"
            )
        click.echo("  Ctrl-C to stop")
        fleet.run(duration_s=duration)
    except KeyboardInterrupt as stop:
        code = 128 + (signal.SIGTERM if isinstance(stop, _Stopped) else signal.SIGINT)
    finally:
        fleet.close()
    click.echo(f"uavtool sitl: stopped at sim time {fleet.now_ns / 1e9:.1f} s")
    for vehicle in fleet.vehicles:
        if vehicle.crashed:
            click.echo(f"  vehicle {vehicle.sysid} crashed: {vehicle.crash_reason}")
    approach = fleet.approach
    if approach.gap_m != float("inf"):
        a, b = approach.sysids
        click.echo(f"  closest approach: vehicles {a} and {b}, bodies {approach.gap_m:.2f} m apart")
    if code:
        sys.exit(code)
