"""``uavtool record``: record a flight someone else flies."""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from types import FrameType

import click

from uavtool.errors import INCOMPLETE_EXIT
from uavtool.terminal import counted

"""``uavtool record`` wrote a whole file, but the vehicle fell silent or the camera stalled
before the end that was asked for."""


@click.command()
@click.option(
    "--connect",
    required=True,
    metavar="URL",
    help="The vehicle or router: udpin:0.0.0.0:14550 (listen, e.g. to MAVProxy's --out), "
    "tcp:HOST:PORT, udpout:HOST:PORT, serial:DEVICE[:BAUD].",
)
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    required=True,
    help="The recording to write (MCAP).",
)
@click.option(
    "--direct",
    is_flag=True,
    help="Send our heartbeat and ask for the telemetry streams (SET_MESSAGE_INTERVAL) — never "
    "while another ground station is heard. Without it nothing at all is sent.",
)
@click.option(
    "--camera",
    default="none",
    show_default=True,
    metavar="none|sim|opencv:N|URL",
    help="sim renders --scene at the vehicle's reported pose; opencv:N or a stream URL reads a "
    "live camera (its newest frame, read on a thread of its own); file://VIDEO reads a video "
    "file a frame at a time.",
)
@click.option("--scene", default="paper", show_default=True, help="The scene --camera sim renders.")
@click.option(
    "--rate",
    "rate_hz",
    type=float,
    default=1.0,
    show_default=True,
    help="Camera frames per second (0: photos only).",
)
@click.option(
    "--photo-every",
    "photo_every_s",
    type=float,
    default=0.0,
    show_default=True,
    metavar="SECONDS",
    help="Also take a photo this often (0: only on the camera commands seen on the link).",
)
@click.option(
    "--hfov",
    "hfov_deg",
    type=float,
    default=60.0,
    show_default=True,
    help="The camera's horizontal field of view, degrees.",
)
@click.option(
    "--gimbal-pitch",
    "gimbal_pitch_deg",
    type=float,
    default=-90.0,
    show_default=True,
    help="The camera's pitch when the vehicle reports no gimbal attitude (−90: straight down).",
)
@click.option(
    "--duration",
    "duration_s",
    type=float,
    default=None,
    metavar="SECONDS",
    help="Stop after this many seconds.",
)
@click.option(
    "--until-landed",
    is_flag=True,
    help="Stop once the vehicle has flown, landed and disarmed (a fleet: every vehicle that "
    "flew, and none of the others is armed).",
)
@click.option(
    "--vehicles",
    type=int,
    default=1,
    show_default=True,
    metavar="N",
    help="Record a fleet on the one link: wait for N vehicles (their heartbeats and positions), "
    "then record each under /uavK (K: its system id), in its own frame around its own home. "
    "--camera none or sim (each vehicle's own view).",
)
@click.option(
    "--timeout",
    "timeout_s",
    type=float,
    default=30.0,
    show_default=True,
    metavar="SECONDS",
    help="Give up (exit 2) when no vehicle (or fewer than --vehicles) is heard in this many "
    "seconds.",
)
def record(
    connect: str,
    output: Path,
    direct: bool,
    camera: str,
    scene: str,
    rate_hz: float,
    photo_every_s: float,
    hfov_deg: float,
    gimbal_pitch_deg: float,
    duration_s: float | None,
    until_landed: bool,
    vehicles: int,
    timeout_s: float,
) -> None:
    """Record a vehicle someone else flies — a pilot, QGroundControl, MAVProxy, an AUTO
    mission, your own code — with its camera, into one MCAP file. Never commands it.

    Every MAVLink frame, the decoded messages, the vehicle's fix and pose, events (mode,
    arming, STATUSTEXT, mission progress) and camera frames with their poses. Photos are
    marked on IMAGE_START_CAPTURE / DO_DIGICAM_CONTROL / CAMERA_FEEDBACK seen on the link
    or every --photo-every seconds. Stops on Ctrl-C, --duration or --until-landed; the
    file is always closed whole.

    A fleet on one link (a radio, a router, several vehicles sending to one port):
    --vehicles N records each of N vehicles under /uavK, the MAVLink frames once.

    \b
    Examples:
      mavproxy.py --master tcp:127.0.0.1:5760 --out udp:127.0.0.1:14551
      uavtool record --connect udpin:127.0.0.1:14551 -o flight.mcap --camera opencv:0
      uavtool record --connect tcp:127.0.0.1:5760 -o sim.mcap --camera sim --until-landed
      uavtool record --connect udpin:127.0.0.1:14550 -o fleet.mcap --vehicles 3 --until-landed
      uavtool replay --vision-only sim.mcap --target target.png -o analysed.mcap
    """
    from uavtool.recorder import RecordConfig
    from uavtool.recorder import record as run

    config = RecordConfig(
        connect=connect,
        output=output,
        direct=direct,
        camera=camera,
        scene=scene,
        rate_hz=rate_hz,
        photo_every_s=photo_every_s,
        hfov_deg=hfov_deg,
        gimbal_pitch_deg=gimbal_pitch_deg,
        duration_s=duration_s,
        until_landed=until_landed,
        timeout_s=timeout_s,
        vehicles=vehicles,
    )
    stop = threading.Event()

    def request_stop(_signum: int, _frame: FrameType | None) -> None:
        stop.set()  # the loop stops between two writes: the file is closed whole

    previous = {s: signal.signal(s, request_stop) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        summary = run(
            config, status=lambda text: click.echo(text, err=True), stop_requested=stop.is_set
        )
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    fleet = f"{len(summary.vehicles)} vehicles, " if len(summary.vehicles) > 1 else ""
    each = "".join(
        f"; vehicle {v.sysid}: {counted(v.telemetry, 'telemetry sample')}, "
        f"{counted(v.frames, 'frame')}, {counted(v.photos, 'photo')}, {counted(v.events, 'event')}"
        for v in (summary.vehicles if fleet else ())
    )
    click.echo(
        f"wrote {summary.path}: {summary.duration_s:.1f} s ({summary.stop.value}), {fleet}"
        f"{summary.messages_in} MAVLink frames in, {summary.messages_out} out, "
        f"{counted(summary.telemetry, 'telemetry sample')}, {counted(summary.frames, 'frame')}, "
        f"{counted(summary.photos, 'photo')}, {counted(summary.events, 'event')}{each}"
    )
    if summary.gaps:
        # the file is whole and kept; what it holds is less than was asked for
        click.echo(f"incomplete: {'; '.join(summary.gaps)}")
        sys.exit(INCOMPLETE_EXIT)
