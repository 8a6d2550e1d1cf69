"""``uavtool sweep``: Monte Carlo sweeps of simulated flights on Dask."""

from __future__ import annotations

import dataclasses
import math
import shlex
import sys
import time
from pathlib import Path

import click

from uavtool.cli.spelling import Command, OldSpelling, looks_like_setting

_OLD_SPELLINGS = (
    OldSpelling(
        "-o",
        "--set",
        "--set KEY.PATH=VALUE (-o now names the output folder)",
        applies=looks_like_setting,
        described="-o KEY.PATH=VALUE",
    ),
    OldSpelling("--override", "--set", "--set KEY.PATH=VALUE"),
    OldSpelling("--out", "--output", "-o/--output"),
)


@click.command(cls=Command, old_spellings=_OLD_SPELLINGS)
@click.argument("spec", type=click.Path(path_type=Path))
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="Change one spec value (TOML syntax), e.g. --set random.draws=50 --set 'grid.seed=[1,2]'.",
)
@click.option(
    "-o",
    "--output",
    "out",
    type=click.Path(path_type=Path),
    default=None,
    metavar="DIR",
    help="Output folder.  [default: the spec's sweep.out, else sweeps/<spec name>]",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Use a running Dask scheduler (e.g. tcp://10.0.0.5:8786). Default: a local cluster.",
)
@click.option(
    "--dashboard",
    default=None,
    metavar="HOST:PORT",
    help="Where the local cluster's Dask dashboard listens, e.g. 0.0.0.0:8787 to reach it from "
    "other machines (anyone who can connect sees the workers, their logs and call stacks).  "
    "[default: 127.0.0.1, a free port]",
)
@click.option(
    "--workers",
    type=int,
    default=None,
    help="Worker processes of the local cluster.  [default: one per core]",
)
@click.option(
    "--timeout",
    "timeout_s",
    type=click.FloatRange(min=0, min_open=True),
    default=None,
    metavar="SECONDS",
    help="Stop a flight after this much vehicle time; it becomes a row with its error "
    "(vehicle seconds, so the same flights stop on any machine).  [default: the spec's "
    "sweep.timeout_s, else none]",
)
@click.option(
    "--resume",
    is_flag=True,
    help="Continue the sweep in the output folder: keep flights whose recording is whole, fly "
    "the rest. The spec and --set values must plan the same flights as when it started.",
)
@click.option("--csv", is_flag=True, help="Write the table as CSV instead of Parquet.")
@click.option("--no-plots", is_flag=True, help="Write no PNG plots.")
@click.option("-q", "--quiet", is_flag=True, help="No progress bar.")
def sweep(
    spec: Path,
    overrides: tuple[str, ...],
    out: Path | None,
    scheduler: str | None,
    dashboard: str | None,
    workers: int | None,
    timeout_s: float | None,
    resume: bool,
    csv: bool,
    no_plots: bool,
    quiet: bool,
) -> None:
    """Fly every flight SPEC describes (scenes x grid x random draws) on the built-in vehicle,
    each in lockstep as a Dask task; write one recording per flight, a results table, a
    summary and plots into the output folder.

    \b
    The same spec gives the same table (apart from wall_s and worker), whatever the number
    of workers. Exit codes: 0 every flight ran (whatever its outcome), 1 some flight raised
    (a row with its error), 2 bad spec or options, 130 interrupted (the folder stays
    consistent: run again with --resume).

    \b
    Examples:
      uavtool sweep wind.toml
      uavtool sweep wind.toml --set random.draws=200 --resume   # as started, interrupted
      uavtool sweep wind.toml --timeout 900 --csv
      uavtool sweep wind.toml --scheduler tcp://head-node:8786 -o /shared/sweeps/wind
    """
    from uavtool.cli.fly import EXIT_CODES
    from uavtool.sweep import format_progress, load_spec, run_sweep
    from uavtool.sweep.spec import TableFormat

    loaded = load_spec(spec, overrides)
    if csv:
        loaded = dataclasses.replace(loaded, table_format=TableFormat.CSV)
    if timeout_s is not None:
        loaded = dataclasses.replace(loaded, timeout_s=timeout_s)
    draw = _Line(quiet)
    result = run_sweep(
        loaded,
        exit_codes=EXIT_CODES,
        out=out,
        scheduler=scheduler,
        workers=workers,
        dashboard=dashboard,
        resume=resume,
        plots=not no_plots,
        progress=lambda p: draw(format_progress(p)),
    )
    draw.end()
    click.echo(result.summary_text)
    click.echo(f"table          {result.table}")
    if result.plots:
        click.echo(f"plots          {result.plots[0].parent}/ ({len(result.plots)} PNG)")
    if result.plots_note:
        click.echo(result.plots_note, err=True)
    if result.interrupted:
        again = ["uavtool", "sweep", str(spec), *(a for o in overrides for a in ("--set", o))]
        again += ["--output", str(result.table.parent)]
        again += ["--timeout", f"{timeout_s:g}"] if timeout_s is not None else []
        again += ["--scheduler", scheduler] if scheduler is not None else []
        again += ["--workers", str(workers)] if workers is not None else []
        again += ["--csv"] if csv else []
        click.echo(
            f"uavtool sweep: interrupted after {len(result.rows)} of {result.summary.planned} "
            f"flights; continue with: {shlex.join([*again, '--resume'])}",
            err=True,
        )
        sys.exit(130)
    sys.exit(1 if result.summary.errors else 0)


class _Line:
    """One progress line on stderr: redrawn in place on a terminal, else a new line at most
    every 10 seconds (logs of batch jobs)."""

    def __init__(self, quiet: bool) -> None:
        self._quiet = quiet
        self._tty = sys.stderr.isatty()
        self._drawn = False
        self._last_s = -math.inf

    def __call__(self, text: str) -> None:
        if self._quiet:
            return
        if self._tty:
            click.echo(f"\r\x1b[2K{text}", nl=False, err=True)
            self._drawn = True
        elif time.monotonic() - self._last_s >= 10.0:
            click.echo(text, err=True)
            self._last_s = time.monotonic()

    def end(self) -> None:
        if self._drawn:
            click.echo(err=True)
