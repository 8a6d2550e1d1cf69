"""A sweep from spec to table: plan the flights, skip those already whole (``--resume``), fly
the rest as Dask tasks through a bounded window (:mod:`~uavtool.sweep.dispatch`), and write the
table, the summary and the plots.

Dask does the scheduling, the retries (a task that raised outside its flight is re-run
``retries`` times; a task whose worker died is re-run elsewhere by the scheduler) and the
completion order; the table is sorted by flight, so it does not depend on either.
"""

from __future__ import annotations

import contextlib
import json
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.mission import SearchMission
from uavtool.plugins import resolve
from uavtool.sweep.cluster import check_cluster_options, open_client
from uavtool.sweep.dispatch import run_tasks
from uavtool.sweep.errors import FlightTimeoutError, OutputExistsError
from uavtool.sweep.layout import SweepLayout
from uavtool.sweep.plan import FlightSpec, dimension_keys, plan_flights
from uavtool.sweep.plots import PlotsUnavailableError, write_plots
from uavtool.sweep.progress import Progress, ProgressCallback
from uavtool.sweep.spec import SweepSpec, TableFormat
from uavtool.sweep.summary import Summary, format_summary, summarise
from uavtool.sweep.table import to_table, write_table
from uavtool.sweep.task import ERROR, error_columns, input_row, run_flight


@dataclass(frozen=True, slots=True)
class SweepResult:
    root: Path
    table: Path
    rows: tuple[dict[str, Any], ...]
    """In flight order; fewer than planned when interrupted."""
    flown: int
    resumed: int
    interrupted: bool
    summary: Summary
    summary_text: str
    plots: tuple[Path, ...]
    plots_note: str
    """Why there are no plots (matplotlib missing), or empty."""


def run_sweep(
    spec: SweepSpec,
    *,
    exit_codes: Mapping[str, int],
    out: Path | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    dashboard: str | None = None,
    resume: bool = False,
    plots: bool = True,
    progress: ProgressCallback | None = None,
    window: int | None = None,
) -> SweepResult:
    """Fly every flight of ``spec``. ``exit_codes`` maps a mission status to the exit code
    ``uavtool fly`` gives it (a table column); ``window`` caps the tasks on the scheduler at
    once (default: a few per worker thread); ``dashboard`` is where the local cluster's
    dashboard listens (default: 127.0.0.1). Raises SpecError, OutputExistsError, or
    InputError for bad cluster options or an unreachable scheduler (before writing
    anything); Ctrl-C returns what was done (``interrupted``)."""
    check_cluster_options(scheduler, workers=workers, dashboard=dashboard)
    flights = plan_flights(spec)
    input_keys = dimension_keys(spec)
    layout = SweepLayout(out if out is not None else spec.out)
    if layout.holds_sweep() and not resume:
        raise OutputExistsError(
            f"{layout.root} already holds a sweep: add --resume to continue it, or choose "
            "another -o/--output"
        )
    stems = [f.stem for f in flights]
    if resume and layout.holds_sweep():
        _same_sweep(layout, spec, stems)  # before anything in the folder changes
    created = not layout.root.exists()
    layout.root.mkdir(parents=True, exist_ok=True)
    layout.remove_partials()
    layout.spec.write_text(spec.text, encoding="utf-8")
    layout.plan.write_text(json.dumps(stems) + "\n", encoding="utf-8")
    rows: dict[int, dict[str, Any]] = {}
    if resume:
        rows = {f.index: r for f in flights if (r := _kept(layout, f, spec)) is not None}
    todo = [f for f in flights if f.index not in rows]
    resumed = len(rows)
    interrupted = False
    if todo:
        tasks = _Tasks(layout, spec, input_keys, exit_codes)
        try:
            _fly_all(todo, rows, tasks, (scheduler, workers, dashboard), window, progress)
        except InputError:  # no cluster to fly on: leave no folder behind that we made
            if created and not rows:
                layout.spec.unlink(missing_ok=True)
                layout.plan.unlink(missing_ok=True)
                with contextlib.suppress(OSError):
                    layout.root.rmdir()
            raise
        except KeyboardInterrupt:
            interrupted = True
            # Flights the workers finished before the driver heard of them: the table must say
            # what the folder holds.
            late = (f for f in todo if f.index not in rows)
            rows |= {f.index: r for f in late if (r := _kept(layout, f, spec)) is not None}
        layout.remove_partials()  # the workers are gone: what they left half-written
    return _finish(spec, layout, flights, rows, input_keys, resumed, interrupted, plots)


def _same_sweep(layout: SweepLayout, spec: SweepSpec, stems: list[str]) -> None:
    """OutputExistsError unless ``spec`` (its overrides applied) plans the flights the folder
    holds: a resume with another spec would mix two sweeps in one table."""
    try:
        held = json.loads(layout.plan.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        held = None
    if isinstance(held, list):
        if held == stems:
            return
        first = next(
            (i for i, (a, b) in enumerate(zip(held, stems, strict=False)) if a != b),
            min(len(held), len(stems)),
        )
        what = (
            f"{len(held)} flights planned there, {len(stems)} now; the first to differ is "
            f"flight {first}"
        )
    else:  # a folder from before plans were kept: the spec as run must be the same text
        try:
            held_text = layout.spec.read_text(encoding="utf-8")  # before --set: --override
            same = held_text.replace("\n# --override ", "\n# --set ") == spec.text
        except OSError:
            same = False
        if same:
            return
        what = f"its {layout.spec.name} differs"
    raise OutputExistsError(
        f"{layout.root} holds another sweep ({what}): --resume takes the spec and --set "
        "values it was started with; or choose another -o/--output"
    )


def _kept(layout: SweepLayout, flight: FlightSpec, spec: SweepSpec) -> dict[str, Any] | None:
    """The row of a flight already done, unless it was stopped under another time limit."""
    row = layout.finished_row(flight)
    if row is None:
        return None
    stopped = str(row.get("error") or "").startswith(FlightTimeoutError.__name__)
    return None if stopped and row.get("timeout_s") != spec.timeout_s else row


@dataclass(frozen=True, slots=True)
class _Tasks:
    """What every flight task of the sweep is given besides its flight."""

    layout: SweepLayout
    spec: SweepSpec
    input_keys: tuple[str, ...]
    exit_codes: Mapping[str, int]

    def kwargs(self) -> dict[str, Any]:
        return {
            "input_keys": self.input_keys,
            "exit_codes": dict(self.exit_codes),
            "timeout_s": self.spec.timeout_s,
        }


def _fly_all(
    todo: list[FlightSpec],
    rows: dict[int, dict[str, Any]],
    tasks: _Tasks,
    cluster: tuple[str | None, int | None, str | None],
    window: int | None,
    progress: ProgressCallback | None,
) -> None:
    total, skipped = len(todo) + len(rows), len(rows)
    report = progress or (lambda _p: None)
    root = str(tasks.layout.root.resolve())
    scheduler, workers, dashboard = cluster
    with open_client(scheduler, workers=workers, dashboard=dashboard) as client:
        report(Progress(0, total, skipped))  # once connected: a refusal is its one line
        t0 = time.perf_counter()
        errors = 0
        finished = run_tasks(
            client,
            run_flight,
            [(flight, root) for flight in todo],
            kwargs=tasks.kwargs(),
            keys=[f"flight-{flight.stem}" for flight in todo],
            retries=tasks.spec.retries,
            window=window,
        )
        for done, task in enumerate(finished, start=1):
            flight = todo[task.index]
            row = task.result
            if task.error is not None:  # out of retries: a row with the error
                row = input_row(flight, tasks.input_keys) | error_columns(task.error)
            rows[flight.index] = row
            errors += row.get("status") == ERROR
            report(Progress(done, total, skipped, errors, time.perf_counter() - t0))


def _finish(
    spec: SweepSpec,
    layout: SweepLayout,
    flights: list[FlightSpec],
    rows: dict[int, dict[str, Any]],
    input_keys: tuple[str, ...],
    resumed: int,
    interrupted: bool,
    plots: bool,
) -> SweepResult:
    ordered = tuple(rows[i] for i in sorted(rows))
    extension = "csv" if spec.table_format is TableFormat.CSV else "parquet"
    table = layout.table(extension)
    write_table(to_table(ordered, input_keys), table)
    searched = issubclass(resolve(spec.mission)[0], SearchMission)
    summary = summarise(ordered, input_keys=input_keys, planned=len(flights), searched=searched)
    text = format_summary(summary)
    layout.summary.write_text(text + "\n", encoding="utf-8")
    layout.summary_json.write_text(json.dumps(summary.to_json(), indent=1) + "\n")
    written: tuple[Path, ...] = ()
    note = ""
    if plots:
        try:
            written = write_plots(summary, layout.plots)
        except PlotsUnavailableError as exc:
            note = str(exc)
    return SweepResult(
        root=layout.root,
        table=table,
        rows=ordered,
        flown=len(ordered) - resumed,
        resumed=resumed,
        interrupted=interrupted,
        summary=summary,
        summary_text=text,
        plots=written,
        plots_note=note,
    )
