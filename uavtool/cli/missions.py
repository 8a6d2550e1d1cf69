"""``uavtool missions``: the missions this installation can fly, and their parameters."""

from __future__ import annotations

import click


@click.command()
@click.argument("name", required=False)
def missions(name: str | None) -> None:
    """List the missions `uavtool fly --mission` takes, or NAME's parameters.

    \b
    Built-in missions come with uavtool; installed packages add theirs through the
    "uavtool.missions" entry-point group (see docs/missions.md).

    \b
    Examples:
      uavtool missions              # every mission, where it comes from
      uavtool missions orbit        # its parameters (--set KEY=VALUE) and defaults
    """
    from uavtool.mission.params import to_dict
    from uavtool.plugins import available, resolve
    from uavtool.terminal import safe_text

    if name is None:
        rows = available()
        width = max(len(r.name) for r in rows)
        for r in rows:
            about = r.summary if not r.error else f"cannot load: {r.error}"
            click.echo(safe_text(f"{r.name:<{width}}  {about}  [{r.origin}: {r.target}]"))
        return
    cls, ref = resolve(name)
    doc = (cls.__doc__ or "").strip().splitlines()
    click.echo(safe_text(f"{ref.name}: {doc[0] if doc else ''}"))
    click.echo(safe_text(f"class {ref.target} (version {ref.version or 'unknown'})"))
    if cls.needs_target:
        click.echo("needs a target picture (--target, or the scene's target rendered)")
    click.echo("parameters (--set KEY=VALUE):")
    for group, values in to_dict(cls.params_type()).items():
        for key, value in values.items():
            click.echo(safe_text(f"  {group}.{key} = {value}"))
