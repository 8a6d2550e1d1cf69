"""``uavtool fly``: fly the search-and-analyze mission and record it."""

from __future__ import annotations

import sys
from pathlib import Path

import click

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


@click.command()
@click.option(
    "--connect",
    default=None,
    metavar="URL",
    help="Vehicle connection: tcp:HOST:PORT, udpin:HOST:PORT, udpout:HOST:PORT or "
    "serial:DEVICE[:BAUD]. Default: start the built-in SITL in-process.",
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
    "the flight (lockstep). Default: max (as fast as the CPU allows); 1 with --rerun.",
)
@click.option(
    "--record",
    type=click.Path(path_type=Path),
    default=None,
    help="Recording path. Default: recordings/<UTC time>.mcap.",
)
@click.option("--no-record", is_flag=True, help="Do not write a recording.")
@click.option(
    "--visit-all", is_flag=True, help="Visit every point of interest, even after a match."
)
@click.option(
    "--param",
    "vehicle_params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Set a vehicle parameter before the flight (ArduPilot names, e.g. WPNAV_SPEED=800).",
)
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="KEY=VALUE",
    help="Set a mission parameter (e.g. mission.look_fill=0.6, vectorize.rdp_epsilon_px=2).",
)
@click.option("--seed", default=0, show_default=True, type=int, help="SITL wind/noise seed.")
@click.option("--noise", is_flag=True, help="Add seeded sensor noise to simulated photos.")
@click.option(
    "--wind", default=None, metavar="SPEED,DIR", help="Built-in SITL wind (m/s, from deg)."
)
@click.option(
    "--link-outage",
    "outages",
    multiple=True,
    metavar="START:DURATION",
    help="Fault injection (built-in SITL): cut the link for DURATION s at sim time START.",
)
@click.option(
    "--timeout",
    default=30.0,
    show_default=True,
    type=float,
    help="Seconds to wait for the vehicle to connect and report its home (vehicle seconds for "
    "the built-in one).",
)
@click.option(
    "--rerun",
    "rerun_target",
    default=None,
    metavar="spawn|web|FILE.rrd",
    help="Stream the flight live to Rerun: the native viewer, the web viewer, or a file.",
)
@click.option("-q", "--quiet", is_flag=True, help="Print only the summary.")
def fly(
    connect: str | None,
    scene: str,
    target: Path | None,
    camera: str,
    speedup: str | None,
    record: Path | None,
    no_record: bool,
    visit_all: bool,
    vehicle_params: tuple[str, ...],
    settings: tuple[str, ...],
    seed: int,
    noise: bool,
    wind: str | None,
    outages: tuple[str, ...],
    timeout: float,
    rerun_target: str | None,
    quiet: bool,
) -> None:
    """Search the scene for the target building, photograph it from three sides and build
    its 3D model; record everything to one MCAP file.

    \b
    Exit codes: 0 completed (target found, model built), 3 partial (target found, no
    model), 4 no match, 5 crashed, 1 aborted / pilot takeover / link lost, 2 bad input.

    \b
    Examples:
      uavtool fly                                  # built-in SITL, scene 'paper'
      uavtool fly --visit-all --scene blocked-front
      uavtool fly --connect tcp:127.0.0.1:5760     # ArduPilot SITL (sim_vehicle.py)
    """
    from uavtool.mission.params import Params, parse_settings, with_overrides
    from uavtool.runner.fly import FlyConfig
    from uavtool.runner.fly import fly as fly_mission
    from uavtool.runner.params import parse_param
    from uavtool.runner.summary import format_progress, format_summary
    from uavtool.sitl.config import parse_outage, parse_wind

    if record is not None and no_record:
        raise click.UsageError("--record and --no-record exclude each other")
    overrides = parse_settings(settings)
    if visit_all:
        overrides["mission.visit_all"] = "true"
    params = with_overrides(Params(), overrides)
    wind_pair = parse_wind(wind) if wind is not None else (0.0, 0.0)
    config = FlyConfig(
        connect=connect,
        scene=scene,
        target=target,
        camera=camera,
        speedup=_speedup(speedup, live=rerun_target is not None),
        record=record,
        no_record=no_record,
        params=params,
        vehicle_params=tuple(parse_param(p) for p in vehicle_params),
        seed=seed,
        noise=noise,
        wind=wind_pair,
        link_outages_s=tuple(parse_outage(o) for o in outages),
        connect_timeout_s=timeout,
        rerun=rerun_target,
    )

    def echo(text: str) -> None:
        if not quiet:
            click.echo(text)

    summary = fly_mission(
        config,
        progress=lambda text, t: echo(format_progress(text, t)),
        status=lambda text: echo(f"uavtool fly: {text}"),
    )
    click.echo(format_summary(summary))
    sys.exit(EXIT_CODES[summary.outcome.status.value])


def _speedup(text: str | None, *, live: bool) -> float | None:
    """``max`` → None (no cap); a positive number → that cap. Watching live defaults to 1."""
    if text is None:
        return 1.0 if live else None
    if text.strip().lower() == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise click.BadParameter(
            f"{text!r}: expected a positive number or 'max'", param_hint="--speedup"
        )
    return value
