"""``uavtool replay DIR_OR_GLOB``: the batch half of ``uavtool replay`` (many recordings on
Dask, one table row each). Not a command of its own: ``uavtool.cli.replay`` hands over here
when its argument is a folder or a glob."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

import click

if TYPE_CHECKING:
    from uavtool.sweep.progress import Progress

_GLOB = set("*?[")


def is_batch(recording: Path) -> bool:
    """A folder or a glob pattern: many recordings."""
    return recording.is_dir() or bool(_GLOB & set(str(recording)))


def replay_batch(
    pattern: Path,
    *,
    check: bool,
    settings: tuple[str, ...],
    params_file: Path | None,
    vision_only: bool,
    target: Path | None,
    out: Path | None,
    scheduler: str | None,
    workers: int | None,
    quiet: bool,
) -> None:
    """Replay every recording; write the table (``-o/--output``, ``.parquet`` or ``.csv``) and its
    summary beside it; exit 1 under ``--check`` unless every one is identical. Under
    ``--vision-only``, the photos of recordings from ``uavtool record`` are matched against
    ``target`` (required for them; a row says so when it is missing)."""
    from uavtool.cli.replay import _params_file
    from uavtool.mission.params import parse_settings
    from uavtool.sweep.replay import (
        IDENTICAL,
        find_recordings,
        format_replay_summary,
        replay_many,
        write_replay_table,
    )

    if target is not None and not vision_only:
        raise click.UsageError("--target is for --vision-only of recordings from uavtool record")
    target_png = _read_target(target) if target is not None else None
    paths = find_recordings(str(pattern))
    overrides: dict[str, object] = _params_file(params_file) if params_file is not None else {}
    overrides.update(parse_settings(settings))
    table = out if out is not None else _default_table()
    if table.suffix not in (".parquet", ".csv"):
        raise click.BadParameter(
            f"{table}: with many recordings, -o/--output names the table: .parquet or .csv",
            param_hint="-o/--output",
        )

    with _progress_line(quiet) as progress:
        batch = replay_many(
            paths,
            overrides=overrides,
            vision_only=vision_only,
            target_png=target_png,
            scheduler=scheduler,
            workers=workers,
            progress=progress,
        )
    write_replay_table(batch, table)
    text = format_replay_summary(batch, total=len(paths), changed_params=bool(overrides))
    table.with_suffix(".txt").write_text(text + "\n", encoding="utf-8")
    click.echo(text)
    click.echo(f"table          {table}")
    if batch.interrupted:
        sys.exit(130)
    whole = all(r.get("result") == IDENTICAL and r.get("status_before") for r in batch.rows)
    if check and not vision_only and not whole:
        sys.exit(1)


def _read_target(target: Path) -> bytes:
    from uavtool.errors import InputError
    from uavtool.images import png_decode

    try:
        png = target.read_bytes()
    except OSError as exc:
        raise InputError(f"--target {target}: cannot read: {exc.strerror}") from None
    png_decode(png, where=f"--target {target}")  # a bad picture is one error, not one per row
    return png


def _default_table() -> Path:
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    return Path("replays") / f"{stamp}.parquet"


def vision_batch(
    pattern: Path,
    spec: str,
    out: Path | None,
    *,
    scheduler: str | None,
    workers: int | None,
    quiet: bool,
) -> None:
    """``--vision`` on many recordings: each one's detections written to ``out`` (a folder,
    default ``vision-<UTC time>``) as ``<name>.vision.mcap``, with a table of them there."""
    from uavtool.plugins import code_dir
    from uavtool.replay.vision import load_function
    from uavtool.sweep.replay import find_recordings
    from uavtool.sweep.vision import format_vision_summary, vision_many, write_vision_table

    load_function(spec)  # here first: a missing module is one error, not one per recording
    paths = find_recordings(str(pattern))
    folder = out if out is not None else Path(f"vision-{datetime.now(UTC):%Y%m%dT%H%M%SZ}")
    if folder.suffix:
        raise click.BadParameter(
            f"{folder}: with many recordings, -o/--output names a folder", param_hint="-o/--output"
        )
    folder.mkdir(parents=True, exist_ok=True)

    with _progress_line(quiet) as progress:
        batch = vision_many(
            paths,
            spec=spec,
            out_dir=folder,
            code_dir=code_dir(),
            scheduler=scheduler,
            workers=workers,
            progress=progress,
        )
    table = folder / "vision.parquet"
    write_vision_table(batch, table)
    click.echo(format_vision_summary(batch, total=len(paths), spec=spec, table=table))
    if batch.interrupted or any(r.get("error") for r in batch.rows):
        sys.exit(1)


@contextmanager
def _progress_line(quiet: bool) -> Iterator[Callable[[Progress], None]]:
    """A progress callback that redraws one line on a terminal's stderr (nothing elsewhere,
    or with ``quiet``), ended with a newline."""
    from uavtool.sweep.progress import format_progress

    shown = not quiet and sys.stderr.isatty()

    def draw(p: Progress) -> None:
        if shown:
            click.echo(f"\r\x1b[2K{format_progress(p, noun='recordings')}", nl=False, err=True)

    yield draw
    if shown:
        click.echo(err=True)
