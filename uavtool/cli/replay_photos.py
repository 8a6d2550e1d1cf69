"""``uavtool replay --vision-only REC --target PNG`` for a recording of ``uavtool record``:
every photo against the target, and ``-o/--output`` a copy with the results."""

from __future__ import annotations

from pathlib import Path

import click

from uavtool.errors import InputError


def replay_photos(
    recording: Path,
    *,
    target: Path | None,
    settings: tuple[str, ...],
    overrides: dict[str, object],
    out: Path | None,
) -> None:
    from uavtool.mission import Params
    from uavtool.mission.params import parse_settings, with_overrides
    from uavtool.recording.files import refuse_same_file
    from uavtool.replay.photos import analyse_photos, write_analysis

    if target is None:
        raise InputError(
            f"{recording}: a recording without a mission has no target picture: "
            "give one with --target PNG"
        )
    try:
        target_png = target.read_bytes()
    except OSError as exc:
        raise InputError(f"--target {target}: cannot read: {exc.strerror}") from None
    if out is not None:
        refuse_same_file(out, [recording, target])
    params = with_overrides(Params(), {**overrides, **parse_settings(settings)})
    analysis = analyse_photos(recording, target_png, params)
    what = "frames (none is marked as a photo)" if analysis.all_frames else "photos"
    click.echo(f"{recording}: {len(analysis.results)} {what} against {target.name}")
    for result in analysis.results:
        click.echo(result.describe())
    matches = analysis.matches
    click.echo(
        f"{len(matches)} match"
        + ("es" if len(matches) != 1 else "")
        + (": frames " + ", ".join(str(r.frame_index) for r in matches) if matches else "")
    )
    if out is not None:
        write_analysis(recording, out, target_png, analysis, params)
        click.echo(f"wrote {out}")
