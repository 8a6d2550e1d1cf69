"""``uavtool view``: show a recording in Rerun (native viewer, web viewer or a .rrd file)."""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import click

from uavtool.cli.options import PORT, check_web_ports
from uavtool.cli.spelling import Command, OldSpelling
from uavtool.errors import INCOMPLETE_EXIT, InputError
from uavtool.terminal import counted


@click.command(cls=Command, old_spellings=(OldSpelling("--port", "--web-port", "--web-port"),))
@click.argument("recording", type=click.Path(path_type=Path))
@click.option(
    "--save",
    type=click.Path(path_type=Path),
    default=None,
    metavar="OUT.rrd",
    help="Write a Rerun file instead of opening a viewer (headless).",
)
@click.option(
    "--web",
    is_flag=True,
    help="Serve the web viewer (Rerun's own server, on 127.0.0.1 unless --bind says "
    "otherwise) and print its URL.",
)
@click.option(
    "--compare",
    type=click.Path(path_type=Path),
    default=None,
    metavar="OTHER.mcap",
    help="A second recording (e.g. a replay) to show beside the first (one vehicle's).",
)
@click.option(
    "--web-port",
    type=PORT,
    default=None,
    metavar="PORT",
    help="With --web: the web viewer's port.  [default: 9090]",
)
@click.option(
    "--bind",
    default="127.0.0.1",
    show_default=True,
    metavar="ADDRESS",
    help="Where the web viewer and its data server listen (--web); 0.0.0.0 serves other "
    "machines too (anyone who can connect sees the flight).",
)
@click.option(
    "--grpc-port",
    type=PORT,
    default=None,
    metavar="PORT",
    help="With --web: the port of the server the viewer reads the recording from.  [default: 9876]",
)
def view(
    recording: Path,
    save: Path | None,
    web: bool,
    compare: Path | None,
    web_port: int | None,
    bind: str,
    grpc_port: int | None,
) -> None:
    """Show RECORDING (an MCAP file from `uavtool fly`) in Rerun: the scene, the route with
    the photo positions, each frame with its vectors, points of interest, scores,
    telemetry, the built model next to the true building, and the text log. A fleet's
    recording (`fly --vehicles N` or `record --vehicles N`) shows every vehicle so, in one
    world, each route where it was flown, with a camera view per vehicle.

    \b
    Examples:
      uavtool view recordings/golden/paper.mcap          # native viewer
      uavtool view recordings/golden/paper.mcap --web    # open the printed URL
      uavtool view paper.mcap --web --web-port 8080 --grpc-port 8081
      uavtool view recordings/golden/paper.mcap --save paper.rrd
      uavtool view paper.mcap --compare paper-replay.mcap
      uavtool view fleet.mcap --save fleet.rrd           # from fly --vehicles 3
    """
    from uavtool.view import view as show

    if save is not None and web:
        raise click.UsageError("--save and --web exclude each other")
    check_web_ports({"--web-port": web_port, "--grpc-port": grpc_port}, web=web, needs="--web")
    if save is None and not web and sys.platform.startswith("linux"):
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise InputError("no display for the native viewer: use --web or --save OUT.rrd")
    from uavtool.recording.info import truncation

    # a cut file is shown up to its cut, and said so last (first when the viewer blocks)
    cuts = [truncation(recording), truncation(compare) if compare is not None else ""]
    cut = "; ".join(c for c in cuts if c)
    result = show(
        recording,
        save=save,
        web=web,
        compare=compare,
        web_port=web_port,
        grpc_port=grpc_port,
        bind=bind,
    )
    c = result.counts
    vehicles = len(result.vehicle_counts)  # a fleet's
    summary = (
        (f"{counted(vehicles, 'vehicle')}, " if vehicles else "")
        + f"{counted(c.frames, 'frame')}, {counted(c.telemetry, 'telemetry sample')}, "
        f"{counted(c.shapes, 'shape')}, {counted(c.recognitions, 'recognition')}, "
        f"{counted(c.models, 'model')}"
        + (f", {counted(c.pictures, 'picture')}" if c.pictures else "")
        + (f", {counted(c.detections, 'detection')}" if c.detections else "")
    )
    if save is not None or not web:
        if save is not None:
            click.echo(f"wrote {save}: {summary}")
        else:
            click.echo(f"sent to the Rerun viewer: {summary}")
            result.viewer.close()
        if cut:
            click.echo(f"incomplete: {cut}")
            sys.exit(INCOMPLETE_EXIT)
        return
    if cut:
        click.echo(f"incomplete: {cut}")
    click.echo(f"web viewer: {result.url}")
    click.echo(f"({summary}; Ctrl-C to stop)")
    signal.signal(signal.SIGTERM, _stop)  # `kill` stops the servers too
    try:
        while True:
            time.sleep(3600)
    finally:
        result.viewer.close()


def _stop(_signum: int, _frame: object) -> None:
    raise KeyboardInterrupt
