"""``uavtool replay``: re-run a recorded mission from its observations."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from uavtool.cli.spelling import Command, OldSpelling
from uavtool.errors import INCOMPLETE_EXIT, FailureError, InputError
from uavtool.terminal import counted

_OLD_SPELLINGS = (
    OldSpelling("--out", "--output", "-o/--output"),
    OldSpelling("--params", "--set-file", "--set-file"),
)


@click.command(cls=Command, old_spellings=_OLD_SPELLINGS)
@click.argument("recording", type=click.Path(path_type=Path))
@click.option(
    "--check",
    is_flag=True,
    help="Every output must equal the recorded one exactly (exit 1 if not).",
)
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="KEY=VALUE",
    help="Override a mission parameter (repeatable), e.g. vectorize.rdp_epsilon_px=3.",
)
@click.option(
    "--set-file",
    "params_file",
    type=click.Path(path_type=Path),
    default=None,
    metavar="FILE.json",
    help="Override mission parameters from a JSON file (nested or dotted keys); --set wins.",
)
@click.option(
    "-o",
    "--output",
    "out",
    type=click.Path(path_type=Path),
    default=None,
    help="Write the replay as a new recording.",
)
@click.option("--vision-only", is_flag=True, help="Only re-run vectorize/match on every frame.")
@click.option(
    "--vision",
    "vision",
    default=None,
    metavar="module:function",
    help="Run your function on every recorded photo and write its detections to a new "
    "recording (-o/--output, default RECORDING.vision.mcap) beside the original's channels.",
)
@click.option(
    "--target",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    metavar="PNG",
    help="--vision-only of a recording from `uavtool record`: the picture to match.",
)
@click.option(
    "--update-golden",
    is_flag=True,
    help="Rewrite RECORDING's outputs (and its .outputs.txt digest) with what the mission "
    "produces now. Deliberate: only when behaviour is meant to change.",
)
@click.option(
    "--refly",
    is_flag=True,
    help="Fly RECORDING's configuration again on the built-in vehicle, in lockstep, from its "
    "metadata alone, and compare the new recording with it message by message (exit 1 at the "
    "first difference). -o/--output keeps the new recording.",
)
@click.option(
    "--mission",
    default=None,
    metavar="module:Class",
    help="The mission's class, when the one RECORDING names is not registered here (a "
    "recording never makes uavtool import code by itself).",
)
@click.option("-q", "--quiet", is_flag=True, help="No progress bar.")
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Many recordings: use this Dask scheduler (default: a local cluster).",
)
@click.option("--workers", type=int, default=None, help="Many recordings: local worker processes.")
def replay(
    recording: Path,
    check: bool,
    settings: tuple[str, ...],
    params_file: Path | None,
    out: Path | None,
    vision_only: bool,
    vision: str | None,
    target: Path | None,
    update_golden: bool,
    refly: bool,
    mission: str | None,
    quiet: bool,
    scheduler: str | None,
    workers: int | None,
) -> None:
    """Feed RECORDING's observations to a fresh mission and compare every output.

    \b
    Examples:
      uavtool replay --check recordings/golden/paper.mcap
      uavtool replay recordings/golden/paper.mcap --set recognize.threshold=0.9
      uavtool replay flight.mcap --set vectorize.rdp_epsilon_px=3 -o replayed.mcap
      uavtool replay --refly recordings/golden/paper.mcap   # vehicle, renderer and mission
      uavtool replay --check recordings/golden -o check.parquet  # a folder or a glob, on Dask
      uavtool replay --vision-only recorded.mcap --target red.png -o analysed.mcap
      uavtool replay --vision-only 'flights/*.mcap' --target red.png -o photos.csv
      uavtool replay flight.mcap --vision my_detector:detect -o detected.mcap
    """
    from uavtool.cli.replay_batch import is_batch, replay_batch

    if vision is not None:
        others = check or settings or params_file or vision_only or target or refly
        if others or update_golden or mission:
            raise InputError("--vision takes only -o/--output")
        if is_batch(recording):
            from uavtool.cli.replay_batch import vision_batch

            vision_batch(recording, vision, out, scheduler=scheduler, workers=workers, quiet=quiet)
        else:
            _vision(recording, vision, out)
        return

    if is_batch(recording):  # a folder or a glob: many recordings on Dask, one table
        if refly or update_golden or mission:
            raise click.UsageError("--refly, --update-golden and --mission take one recording")
        replay_batch(
            recording,
            check=check,
            settings=settings,
            params_file=params_file,
            vision_only=vision_only,
            target=target,
            out=out,
            scheduler=scheduler,
            workers=workers,
            quiet=quiet,
        )
        return
    from uavtool.mission import SearchMission
    from uavtool.mission.params import parse_settings, with_overrides
    from uavtool.recording.files import refuse_same_file
    from uavtool.replay import load_flight, reanalyse_frames
    from uavtool.replay import replay as run_replay

    if vision_only and not refly and not update_golden:
        from uavtool.replay.photos import is_recorded_flight

        if is_recorded_flight(recording):  # from `uavtool record`: no mission, only photos
            from uavtool.cli.replay_photos import replay_photos

            extra = _params_file(params_file) if params_file is not None else {}
            replay_photos(recording, target=target, settings=settings, overrides=extra, out=out)
            return
    if target is not None:
        raise click.UsageError("--target is for --vision-only of a recording from uavtool record")
    if refly:
        if settings or params_file or vision_only or update_golden or check:
            raise InputError(
                "--refly flies the recorded configuration as it is: it takes only -o/--output "
                "(and --mission)"
            )
        _refly(recording, out, mission)
        return
    if update_golden:
        from uavtool.replay.golden import update_golden as update

        before, after = update(recording)
        click.echo(
            f"{recording}: outputs rewritten ({before} → {after}); review the diff of "
            f"{recording.with_suffix('.outputs.txt')}"
        )
        return
    if out is not None:
        refuse_same_file(out, [recording])  # now, not after the whole replay
    from uavtool.replay.load import is_fleet

    if is_fleet(recording):
        if out is not None or vision_only:
            raise InputError(
                f"{recording}: a fleet's recording: replay --check and --set work on it, "
                "-o/--output and --vision-only not yet"
            )
        extra = _params_file(params_file) if params_file is not None else {}
        _replay_fleet(recording, check, {**extra, **parse_settings(settings)}, mission)
        return
    flight = load_flight(recording, mission=mission)
    overrides: dict[str, object] = {}
    if params_file is not None:
        overrides.update(_params_file(params_file))
    overrides.update(parse_settings(settings))
    params = with_overrides(flight.params, overrides)
    changed = bool(overrides)
    if flight.truncated and check:
        raise InputError(
            f"{recording}: the recording is truncated (cut while writing); --check needs a whole "
            f"file. `uavtool info --recover {recording} -o fixed.mcap` saves what it holds"
        )
    if check and not vision_only and not flight.has_outcome:
        raise FailureError(
            f"{recording}: no Outcome among its {len(flight.outputs)} recorded outputs: the "
            "mission did not finish, or its end was lost; --check cannot vouch for it"
        )
    if flight.truncated:
        click.echo(
            f"{recording}: truncated recording: replaying the "
            f"{len(flight.observations)} observations it holds",
            err=True,
        )
    if not vision_only:
        with (
            click.progressbar(length=len(flight.observations), label="replay", file=sys.stderr)
            if not quiet and sys.stderr.isatty()  # else click prints its label alone
            else _NoBar() as bar
        ):
            last = [0]

            def progress(done: int, _total: int) -> None:
                bar.update(done - last[0])
                last[0] = done

            result = run_replay(flight, params, progress=progress)
        click.echo(
            f"{recording}: {result.steps} observations replayed, {len(result.outputs)} outputs "
            f"({len(flight.outputs)} recorded)"
        )
        if result.first_difference is None and result.divergence is None:
            if flight.truncated:
                click.echo("the same up to the cut: every output equals the recorded one")
            else:
                click.echo("identical: every output equals the recorded one")
        elif result.first_difference is not None:
            click.echo(f"first difference: {result.first_difference.describe()}")
        if result.divergence is not None:
            click.echo(f"diverged at step {result.divergence.step}: {result.divergence.reason}")
            if issubclass(flight.mission, SearchMission):
                click.echo(
                    "mission stopped there; per-frame vision continues on every recorded frame"
                )
            else:
                click.echo("mission stopped there")
        if out is not None:
            from uavtool.replay.write import write_replay  # mcap's writer: ~30 ms

            write_replay(
                recording, out, result.outputs, result.blobs, params, outcome=result.outcome
            )
            click.echo(f"wrote {out}")
    if changed or vision_only:
        for change in reanalyse_frames(flight, params):
            if change.changed or vision_only:
                click.echo(change.describe())
    if check and not vision_only and result.first_difference is not None:
        sys.exit(1)
    if flight.truncated:
        from uavtool.recording.info import truncation

        click.echo(f"incomplete: {truncation(recording)}")
        sys.exit(INCOMPLETE_EXIT)


def _replay_fleet(
    recording: Path, check: bool, overrides: dict[str, object], mission: str | None
) -> None:
    """Replay every member of a fleet; exit 1 under --check at any difference."""
    from uavtool.mission.params import with_overrides
    from uavtool.replay.fleet import replay_fleet
    from uavtool.replay.load import load_fleet

    fleet = load_fleet(recording, mission=mission)
    if fleet.truncated and check:
        raise InputError(
            f"{recording}: the recording is truncated (cut while writing); --check needs a whole "
            "file"
        )
    params = with_overrides(fleet.params, overrides)
    results = replay_fleet(fleet, params)
    differs = False
    for vehicle, result in zip(fleet.vehicles, results, strict=True):
        head = (
            f"{recording}: vehicle {vehicle.sysid}: {result.steps} observations replayed, "
            f"{len(result.outputs)} outputs ({len(vehicle.outputs)} recorded)"
        )
        if result.identical:
            click.echo(f"{head}; identical")
            continue
        differs = differs or result.first_difference is not None
        if result.first_difference is not None:
            click.echo(f"{head}; first difference: {result.first_difference.describe()}")
        if result.divergence is not None:
            d = result.divergence
            click.echo(f"{head}; diverged at step {d.step}: {d.reason}")
    if not differs and all(r.identical for r in results):
        click.echo("identical: every output of every vehicle equals the recorded one")
    if check and differs:
        sys.exit(1)
    if fleet.truncated:
        from uavtool.recording.info import truncation

        click.echo(f"incomplete: {truncation(recording)}")
        sys.exit(INCOMPLETE_EXIT)


def _vision(recording: Path, spec: str, out: Path | None) -> None:
    from uavtool.replay.vision import load_function, run_vision

    function = load_function(spec)
    target = out if out is not None else recording.with_suffix(".vision.mcap")
    run = run_vision(recording, target, spec, function)
    click.echo(
        f"{recording}: {spec} on {counted(run.frames, 'photo')}: "
        f"{counted(run.detections, 'detection')}; wrote {run.out}"
    )


def _refly(recording: Path, out: Path | None, mission: str | None) -> None:
    from uavtool.replay.refly import refly

    result = refly(recording, out=out, mission=mission)
    s = result.summary
    click.echo(
        f"{recording}: flown again in lockstep, {s.vehicle_time_s:.1f} s of vehicle time in "
        f"{s.flight_wall_s:.1f} s; {result.messages} messages compared"
        + (f"; new recording {out}" if out is not None else "")
    )
    if result.first_difference is None:
        click.echo("identical: the new recording equals the old one")
        return
    click.echo(f"first difference: {result.first_difference}")
    sys.exit(1)


class _NoBar:
    def __enter__(self) -> _NoBar:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    def update(self, n: int) -> None:
        pass


def _params_file(path: Path) -> dict[str, object]:
    try:
        data = json.loads(path.read_text())
    except OSError as exc:
        raise InputError(f"--set-file {path}: cannot read: {exc.strerror}") from None
    except ValueError as exc:
        raise InputError(f"--set-file {path}: not JSON: {exc}") from None
    if not isinstance(data, dict):
        raise InputError(f"--set-file {path}: expected a JSON object")
    return data
