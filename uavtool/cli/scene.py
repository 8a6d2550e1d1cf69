"""``uavtool scene``: list, validate, render and generate scenes."""

from __future__ import annotations

from pathlib import Path

import click

from uavtool.errors import InputError


def _floats(text: str, n: int, option: str, example: str) -> tuple[float, ...]:
    try:
        values = tuple(float(p) for p in text.split(","))
    except ValueError:
        values = ()
    if len(values) != n:
        raise InputError(f"{option} {text!r}: expected {n} comma-separated numbers, e.g. {example}")
    return values


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(p) for p in text.lower().split("x"))
    except ValueError:
        raise InputError(f"--size {text!r}: expected WIDTHxHEIGHT, e.g. 640x480") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise InputError(f"--size {text!r}: width and height must be 16..8192 pixels")
    return w, h


@click.group()
def scene() -> None:
    """List, validate, render and generate world scenes.

    SCENE is a built-in scene name (see `uavtool scene list`) or a YAML/TOML/JSON file.

    \b
    Example:
      uavtool scene render paper --pos 0,0,45 --pitch -90 -o nadir.png
    """


@scene.command("list")
def list_scenes() -> None:
    """List the built-in scenes.

    \b
    Example:
      uavtool scene list
    """
    from uavtool.world import builtin_scene_names, load_scene

    for name in builtin_scene_names():
        s = load_scene(name)
        click.echo(
            f"{name:16s} {len(s.buildings):3d} buildings, target {s.target!r}: {s.description}"
        )


@scene.command()
@click.argument("scene_ref", metavar="SCENE")
def validate(scene_ref: str) -> None:
    """Check a scene file; print a summary or the first error (exit 2).

    \b
    Example:
      uavtool scene validate my-scene.yaml
    """
    from uavtool.world import load_scene

    s = load_scene(scene_ref)
    blocks = sum(len(b.blocks) for b in s.buildings)
    click.echo(
        f"{scene_ref}: ok: {len(s.buildings)} buildings, {blocks} blocks, target {s.target!r}"
    )


@scene.command()
@click.argument("scene_ref", metavar="SCENE")
@click.option(
    "--pos", required=True, metavar="E,N,U", help="Camera position, metres east,north,up of home."
)
@click.option(
    "--yaw", default=0.0, show_default=True, help="Camera heading, degrees clockwise from north."
)
@click.option(
    "--pitch",
    default=-90.0,
    show_default=True,
    help="Gimbal pitch, degrees (-90 nadir, 0 forward).",
)
@click.option(
    "--size", default="640x480", show_default=True, metavar="WxH", help="Image size in pixels."
)
@click.option("--fov", default=60.0, show_default=True, help="Horizontal field of view, degrees.")
@click.option("--noise-seed", default=None, type=int, help="Add seeded sensor noise.")
@click.option(
    "-o", "--output", required=True, type=click.Path(path_type=Path), help="PNG file to write."
)
def render(
    scene_ref: str,
    pos: str,
    yaw: float,
    pitch: float,
    size: str,
    fov: float,
    noise_seed: int | None,
    output: Path,
) -> None:
    """Render one camera frame of SCENE to a PNG.

    \b
    Examples:
      uavtool scene render paper --pos 0,0,45 --pitch -90 -o overview.png
      uavtool scene render paper --pos 10,-30,3 --yaw 0 --pitch 0 -o front.png
    """
    from uavtool.camera import CameraPose, Intrinsics
    from uavtool.world import load_scene
    from uavtool.world import render as render_frame
    from uavtool.world.images import write_png

    e, n, u = _floats(pos, 3, "--pos", "10,-30,3")
    if not -90.0 <= pitch <= 90.0:
        raise InputError(f"--pitch {pitch}: must be in [-90, 90] degrees")
    width, height = _size(size)
    intrinsics = Intrinsics.from_hfov(width_px=width, height_px=height, hfov_deg=fov)
    s = load_scene(scene_ref)
    write_png(
        output,
        render_frame(s, CameraPose((e, n, u), yaw, pitch), intrinsics, noise_seed=noise_seed),
    )


@scene.command()
@click.argument("scene_ref", metavar="SCENE")
@click.option(
    "--size", default="960x720", show_default=True, metavar="WxH", help="Image size in pixels."
)
@click.option(
    "-o", "--output", required=True, type=click.Path(path_type=Path), help="PNG file to write."
)
def show(scene_ref: str, size: str, output: Path) -> None:
    """Render an overview of SCENE from above, north up, buildings labelled.

    \b
    Example:
      uavtool scene show dense -o dense.png
    """
    from uavtool.world import load_scene
    from uavtool.world.images import render_overview, write_png

    width, height = _size(size)
    write_png(output, render_overview(load_scene(scene_ref), width_px=width, height_px=height))


@scene.command("random")
@click.option(
    "--seed", required=True, type=int, help="Random seed; the same seed gives the same file."
)
@click.option("--buildings", default=8, show_default=True, type=int, help="Number of buildings.")
@click.option(
    "--margin", default=4.0, show_default=True, help="Minimum gap between buildings, metres."
)
@click.option(
    "-o",
    "--output",
    required=True,
    type=click.Path(path_type=Path),
    help="Scene file to write (.yaml or .json).",
)
def random_scene(seed: int, buildings: int, margin: float, output: Path) -> None:
    """Generate a random scene file from a seed.

    \b
    Example:
      uavtool scene random --seed 7 --buildings 10 -o random7.yaml
      uavtool scene show random7.yaml -o random7.png
    """
    from uavtool.world.generator import generate_scene
    from uavtool.world.scene import dump_scene

    s = generate_scene(seed=seed, buildings=buildings, margin_m=margin)
    suffix = output.suffix.lower()
    if suffix not in (".yaml", ".yml", ".json"):
        raise InputError(f"{output}: output must end in .yaml, .yml or .json")
    try:
        output.write_text(dump_scene(s, suffix=suffix), encoding="utf-8")
    except OSError as exc:
        raise InputError(f"{output}: cannot write: {exc.strerror}") from None
    click.echo(f"{output}: {len(s.buildings)} buildings, target {s.target!r}")
