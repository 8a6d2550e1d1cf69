"""``uavtool info``, ``uavtool export`` and ``uavtool import``: inspect, repair and convert
recordings. Heavy imports happen inside the commands so ``uavtool --help`` stays fast."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from uavtool.errors import INCOMPLETE_EXIT, InputError

# No dir_okay=False: click would answer a directory with a usage screen; the readers and
# writers refuse one in a line of their own (what it is, and what was expected).
_PATH = click.Path(path_type=Path)


@click.command()
@click.argument("rec", metavar="RECORDING", type=_PATH)
@click.option(
    "--verify/--no-verify",
    default=True,
    show_default=True,
    help="Read every chunk and check its CRC; --no-verify reads the summary alone (instant "
    "on any size, but finds no damage inside the chunks).",
)
@click.option("--recover", is_flag=True, help="Rewrite everything readable as a whole file.")
@click.option("-o", "--output", type=_PATH, help="Where --recover writes (required with it).")
@click.option("--json", "as_json", is_flag=True, help="Print the report as one JSON object.")
def info(rec: Path, verify: bool, recover: bool, output: Path | None, as_json: bool) -> None:
    """Show a recording's duration, topics, frames, outcome and file health.

    Every chunk's CRC is checked: a corrupt chunk is reported with its topics, log times
    and the messages lost, and the command then exits 2. A truncated file (the recorder
    crashed) is reported, not refused. --recover copies what the file still holds into a
    whole, indexed file, leaving corrupt chunks out.

    \b
    Example:
      uavtool info recordings/golden/paper.mcap
      uavtool info --recover crashed.mcap -o fixed.mcap
      uavtool info --json recordings/golden/paper.mcap
    """
    if recover != (output is not None):
        raise click.UsageError("--recover and -o/--output go together")
    from uavtool.recording import info as recording_info

    summary = recording_info.summarize(rec, verify=verify or recover)
    if as_json:
        import json

        click.echo(json.dumps(recording_info.info_json(summary), indent=2))
    else:
        click.echo(recording_info.format_info(summary))
    if recover and output is not None:
        from uavtool.recording.recovery import recover as do_recover

        result = do_recover(rec, output)
        for dropped in result.dropped:
            click.echo(f"dropped {dropped}")
        click.echo(
            f"recovered {result.messages} messages on {result.channels} channels to {output}"
            + (f"; {result.messages_lost} messages lost" if result.messages_lost else "")
        )
        return
    problem = recording_info.damage_problem(summary)
    if problem:
        raise InputError(f"{rec}: {problem}")


@click.command()
@click.argument("rec", metavar="RECORDING", type=_PATH)
@click.option("--tlog", "tlog", type=_PATH, default=None, help="Write /mavlink/raw as a .tlog.")
@click.option(
    "--frames",
    "frames_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    metavar="DIR",
    help="Write every camera frame as DIR/frame_NNNN.png with a .json sidecar of its pose "
    "(and DIR/target.png when the recording holds a target picture).",
)
@click.option(
    "--layout",
    "layout",
    type=_PATH,
    default=None,
    help="Write a Foxglove / Lichtblick layout for the recording (JSON): a 3D view of the "
    "route, photo poses and model, the camera image, the target, attitude plots and the log; "
    "a fleet's: a tab per vehicle (its 3D view, camera and log), a map and plots of them all.",
)
@click.option(
    "--model", "model", type=_PATH, default=None, metavar="FILE.glb",
    help="Write the 3D model the flight built (glTF binary, as recorded).",
)  # fmt: skip
@click.option(
    "--target", "target", type=_PATH, default=None, metavar="FILE.png",
    help="Write the target picture the flight searched for (PNG, as recorded).",
)  # fmt: skip
def export(
    rec: Path,
    tlog: Path | None,
    frames_dir: Path | None,
    layout: Path | None,
    model: Path | None,
    target: Path | None,
) -> None:
    """Export a recording's MAVLink frames to a telemetry log, its camera frames to PNG, a
    Foxglove / Lichtblick layout that shows it, the model it built or its target picture.

    The .tlog opens in MAVProxy, MAVExplorer and mavlogdump.py. The layout is imported in
    Foxglove or Lichtblick with Layouts → Import from file; it switches on the 3D topics
    and aims the 3D view at the flown path (a fleet's: each vehicle's in a tab of its own,
    beside a map of the whole fleet).

    \b
    Example:
      uavtool export flight.mcap --tlog flight.tlog && mavlogdump.py flight.tlog
      uavtool export flight.mcap --frames frames/     # frame_0000.png + frame_0000.json …
      uavtool export recordings/golden/paper.mcap --layout paper.layout.json
      uavtool export flight.mcap --model model.glb --target target.png
    """
    if (tlog, frames_dir, layout, model, target) == (None,) * 5:
        raise click.UsageError(
            "say what to export: --tlog FILE, --frames DIR, --layout FILE, --model FILE.glb "
            "and/or --target FILE.png"
        )
    from uavtool.recording.info import truncation

    cut = truncation(rec)  # a cut file is exported up to its cut, and said so last
    if tlog is not None:
        from uavtool.recording.tlog import export_tlog

        result = export_tlog(rec, tlog)
        click.echo(f"wrote {result.frames} MAVLink frames to {tlog}")
    vehicles = _fleet(rec)
    if frames_dir is not None:
        from uavtool.recording.frames import export_frames

        if vehicles and frames_dir.exists() and any(frames_dir.iterdir()):
            raise InputError(f"{frames_dir}: exists and is not an empty folder: choose another")
        for k in vehicles or (None,):
            folder = frames_dir if k is None else frames_dir / f"uav{k}"
            frames = export_frames(rec, folder, prefix="" if k is None else f"/uav{k}")
            with_target = " and target.png" if frames.target else ""
            click.echo(
                f"wrote {frames.frames} frames ({frames.with_pose} with a pose){with_target} to "
                f"{folder}"
            )
    if layout is not None:
        from uavtool.recording.foxglove_layout import export_layout

        panels = export_layout(rec, layout)["configById"]
        click.echo(f"wrote a layout of {len(panels)} panels to {layout}")
    if model is not None:
        from uavtool.recording.artifacts import export_model

        click.echo(f"wrote the model ({export_model(rec, model)} bytes of GLB) to {model}")
    if target is not None:
        from uavtool.recording.artifacts import export_target

        click.echo(f"wrote the target picture ({export_target(rec, target)} bytes) to {target}")
    if cut:
        click.echo(f"incomplete: {cut}")
        sys.exit(INCOMPLETE_EXIT)


def _fleet(rec: Path) -> tuple[int, ...]:
    """A fleet's vehicles (system ids), () for one vehicle's recording."""
    from uavtool.recording.info import summarize

    return tuple(k for k, _ in summarize(rec, verify=False).vehicles)


@click.command(name="import")
@click.argument("tlog", type=_PATH)
@click.option("-o", "--output", type=_PATH, required=True, help="The recording to write.")
@click.option(
    "--gcs-sysid",
    type=click.IntRange(0, 255),
    default=255,
    show_default=True,
    help="System id of the ground station: its frames are recorded as sent ('out').",
)
def import_(tlog: Path, output: Path, gcs_sysid: int) -> None:
    """Turn a telemetry log (MAVProxy, QGroundControl) into a recording.

    \b
    Example:
      uavtool import 2024-05-01_flight.tlog -o flight.mcap && uavtool info flight.mcap
    """
    from uavtool.recording.tlog import import_tlog

    result = import_tlog(tlog, output, gcs_sysid=gcs_sysid)
    skipped = f" (skipped {result.skipped_bytes} unreadable bytes)" if result.skipped_bytes else ""
    click.echo(f"imported {result.frames} MAVLink frames to {output}{skipped}")
