"""``uavtool sitl``: run the built-in MAVLink vehicle."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import click


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
@click.option("--home", default=None, metavar="LAT,LON,ALT,HDG", help="Home position and heading.")
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
    home: str | None,
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
    """
    from uavtool.sitl import Sitl, SitlConfig, parse_home, parse_signing_key
    from uavtool.sitl.config import (
        ARMING_SETTLE_S,
        DEFAULT_ENDPOINTS,
        parse_duration,
        parse_outage,
        parse_param,
        parse_wind,
    )
    from uavtool.sitl.mount import SERVO_ROLL_TRIM_DEG
    from uavtool.sitl.params import load_param_file

    kwargs: dict[str, object] = {}
    home_point = None
    if home is not None:
        home_point, kwargs["home_heading_deg"] = parse_home(home)
        kwargs["home"] = home_point
    scene_text = ""
    if scene is not None:
        from uavtool.world import load_scene
        from uavtool.world.obstacles import scene_obstacles

        loaded = load_scene(scene)
        if home_point is None:
            kwargs["home"], kwargs["home_heading_deg"] = loaded.home, loaded.home_heading_deg
        # With --home the buildings stay where the scene puts them on the map.
        kwargs["obstacles"] = obstacles = scene_obstacles(loaded, home=home_point)
        scene_text = f", scene {loaded.name!r} ({len(obstacles)} obstacles)"
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
