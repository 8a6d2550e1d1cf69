"""``uavtool scene``: list, validate, render and generate scenes."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import click

from uavtool.checks import Range
from uavtool.cli.options import SEED, Number, Numbers
from uavtool.errors import InputError
from uavtool.fifo import reader_held

if TYPE_CHECKING:
    from uavtool.world.hard import HardSceneInfo
    from uavtool.world.scene import Scene

_EXTENT = Range(-100_000.0, 100_000.0)  # a camera within 100 km of home
_POS = Numbers(",", (("E", _EXTENT), ("N", _EXTENT), ("U", _EXTENT)), example="10,-30,3")


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
    "--pos",
    required=True,
    type=_POS,
    metavar="E,N,U",
    help="Camera position, metres east,north,up of home.",
)
@click.option(
    "--yaw",
    default=0.0,
    show_default=True,
    type=Number(Range(-360.0, 360.0)),
    help="Camera heading, degrees clockwise from north.",
)
@click.option(
    "--pitch",
    default=-90.0,
    show_default=True,
    type=Number(Range(-90.0, 90.0)),
    help="Gimbal pitch, degrees (-90 nadir, 0 forward).",
)
@click.option(
    "--size", default="640x480", show_default=True, metavar="WxH", help="Image size in pixels."
)
@click.option(
    "--fov",
    default=60.0,
    show_default=True,
    type=Number(Range(1.0, 170.0)),
    help="Horizontal field of view, degrees.",
)
@click.option("--noise-seed", default=None, type=SEED, help="Add seeded sensor noise.")
@click.option(
    "-o", "--output", required=True, type=click.Path(path_type=Path), help="PNG file to write."
)
def render(
    scene_ref: str,
    pos: tuple[float, float, float],
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

    width, height = _size(size)
    intrinsics = Intrinsics.from_hfov(width_px=width, height_px=height, hfov_deg=fov)
    s = load_scene(scene_ref)
    write_png(
        output,
        render_frame(s, CameraPose(pos, yaw, pitch), intrinsics, noise_seed=noise_seed),
    )


@scene.command()
@click.argument("scene_ref", metavar="SCENE")
@click.option(
    "-o", "--output", required=True, type=click.Path(path_type=Path), help="PNG file to write."
)
def target(scene_ref: str, output: Path) -> None:
    """Write SCENE's target picture: the target building alone, from above.

    It is the picture `uavtool fly` searches for when no --target is given (same camera:
    640x480, 60 degrees across).

    \b
    Example:
      uavtool scene target paper -o target.png
      uavtool fly --target target.png
    """
    from uavtool.camera import Intrinsics
    from uavtool.runner.fly import FlyConfig, target_picture
    from uavtool.world import load_scene

    config = FlyConfig()
    (width, height), hfov = config.size_px, config.hfov_deg
    intrinsics = Intrinsics.from_hfov(width_px=width, height_px=height, hfov_deg=hfov)
    picture = target_picture(load_scene(scene_ref), intrinsics)
    try:
        with reader_held(output):
            output.write_bytes(picture)
    except OSError as exc:
        raise click.FileError(str(output), exc.strerror) from None
    click.echo(f"wrote {output}: the target building of {scene_ref}")


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
    "--seed", required=True, type=SEED, help="Random seed; the same seed gives the same file."
)
@click.option(
    "--buildings",
    default=None,
    type=Number(Range(1), integer=True),
    help="Number of buildings.  [default: 8; with --hard 5-8, drawn from the seed; with "
    "--town 6-9, 12-16 in a dense block]",
)
@click.option(
    "--margin",
    default=4.0,
    show_default=True,
    type=Number(),
    help="Minimum gap between buildings, metres.",
)
@click.option(
    "--hard",
    is_flag=True,
    help="A hard scene: decoys of the target (mirror image in a close hue, scaled copy, "
    "one vertex moved), stepped towers, arches, 3-25 m tall, spread past one overview.",
)
@click.option(
    "--spread",
    default=None,
    type=Number(),
    help="With --hard: half-side of the square around home the buildings stand in, "
    "metres.  [default: 35]",
)
@click.option("--overhang", is_flag=True, help="With --hard: home under an arch 5-7 m up.")
@click.option(
    "--town",
    is_flag=True,
    help="With --hard: scenes of a town as well (HardOptions.town()): grey, white, black and "
    "grey-blue roofs, darker shades of a building's hue, decoys in the target's colour that "
    "differ by a courtyard or a wing, courtyard and 3-5 m targets, 30-60 m towers (one maybe "
    "beside home), dense blocks of 12-16 buildings 2-3 m apart; each in about a fifth to a "
    "third of the scenes. The file's description names them.",
)
@click.option(
    "--random-home",
    is_flag=True,
    help="With --hard: home anywhere within 60° of the equator, the vehicle facing any way "
    "(the buildings around home are the seed's own).",
)
@click.option(
    "--anywhere",
    is_flag=True,
    help="With --hard: home anywhere on Earth to 85° of latitude, in a third of the scenes "
    "with the 180th meridian through the buildings; the vehicle facing any way (wins over "
    "--random-home).",
)
@click.option(
    "--world",
    is_flag=True,
    help="With --hard: every world class below on (any light, ground colour, ground areas, "
    "texture, near shapes).",
)
@click.option(
    "--light",
    is_flag=True,
    help="With --hard: the sun 5-90° up from any azimuth, ambient 0.15-0.8.",
)
@click.option(
    "--ground-colour",
    is_flag=True,
    help="With --hard: ground of any colour (greens, browns), its hue away from the target's by "
    "the vectorizer's hue tolerance.",
)
@click.option(
    "--ground-areas",
    is_flag=True,
    help="With --hard: 2-6 lawns, roads, car parks and fields around home (flat, not buildings).",
)
@click.option(
    "--texture", is_flag=True, help="With --hard: seeded grain or noise on the ground, 4-14 DN."
)
@click.option(
    "--near-shapes",
    is_flag=True,
    help="With --hard: 1-2 buildings of the target's colour and height whose outline is almost "
    "the target's (aspect 5-10 % off, a trapezoid, a chamfered or notched corner, an arm 15 % "
    "shorter).",
)
@click.option(
    "-o",
    "--output",
    required=True,
    type=click.Path(path_type=Path),
    help="Scene file to write (.yaml or .json).",
)
def random_scene(
    seed: int,
    buildings: int | None,
    margin: float,
    hard: bool,
    spread: float | None,
    overhang: bool,
    town: bool,
    random_home: bool,
    anywhere: bool,
    world: bool,
    light: bool,
    ground_colour: bool,
    ground_areas: bool,
    texture: bool,
    near_shapes: bool,
    output: Path,
) -> None:
    """Generate a random scene file from a seed.

    With --hard, the target has decoys (mirror image, scaled copy, near-identical shape),
    some buildings are stepped towers or arches, and they stand wider apart than one
    photo from 45 m covers; the file's description names the decoys. --town adds what a
    town has and the search was not tuned on: grey roofs, darker shades, same-colour
    decoys with a yard or a wing more or less, courtyards, small targets, tall towers,
    home beside a tower, dense blocks. --world adds any light, any ground (colour, areas,
    texture) and near shapes of the target in its colour; each of them has its own flag.

    \b
    Examples:
      uavtool scene random --seed 7 --buildings 10 -o random7.yaml
      uavtool scene show random7.yaml -o random7.png
      uavtool scene random --hard --seed 7 -o hard7.yaml
      uavtool scene random --hard --town --seed 7 -o town7.yaml
      uavtool scene random --hard --town --world --seed 7 -o world7.yaml
    """
    from uavtool.world.scene import dump_scene

    suffix = output.suffix.lower()
    if suffix not in (".yaml", ".yml", ".json"):
        raise InputError(f"{output}: output must end in .yaml, .yml or .json")
    knobs = {
        "any_light": light,
        "any_ground": ground_colour,
        "ground_areas": ground_areas,
        "ground_texture": texture,
        "near_shapes": near_shapes,
    }
    if world:
        knobs = dict.fromkeys(knobs, True)
    if hard:
        s, info = _hard_scene(
            seed, buildings, margin, spread, overhang, town, random_home, anywhere, knobs
        )
    else:
        from uavtool.world.generator import generate_scene

        for flag, given in (
            ("--spread", spread is not None),
            ("--overhang", overhang),
            ("--town", town),
            ("--random-home", random_home),
            ("--anywhere", anywhere),
            ("--world", world),
            ("--light", light),
            ("--ground-colour", ground_colour),
            ("--ground-areas", ground_areas),
            ("--texture", texture),
            ("--near-shapes", near_shapes),
        ):
            if given:
                raise InputError(f"{flag} needs --hard")
        s = generate_scene(
            seed=seed, buildings=8 if buildings is None else buildings, margin_m=margin
        )
    try:
        with reader_held(output):
            output.write_text(dump_scene(s, suffix=suffix), encoding="utf-8")
    except OSError as exc:
        raise InputError(f"{output}: cannot write: {exc.strerror}") from None
    click.echo(f"{output}: {len(s.buildings)} buildings, target {s.target!r}")
    if hard:
        click.echo(info.summary())


def _hard_scene(
    seed: int,
    buildings: int | None,
    margin: float,
    spread: float | None,
    overhang: bool,
    town: bool,
    random_home: bool,
    anywhere: bool,
    knobs: dict[str, bool],
) -> tuple[Scene, HardSceneInfo]:
    from dataclasses import replace

    from uavtool.world.hard import MAX_HARD_BUILDINGS, HardOptions, generate_hard_scene_with_info

    default = HardOptions.town() if town else HardOptions()
    if buildings is not None and not 1 <= buildings <= MAX_HARD_BUILDINGS:
        raise InputError(
            f"--buildings must be in 1..{MAX_HARD_BUILDINGS} with --hard, got {buildings}"
        )
    # HardOptions checks the rest (SceneError, exit 2)
    options = replace(
        default,
        min_buildings=default.min_buildings if buildings is None else buildings,
        max_buildings=default.max_buildings if buildings is None else buildings,
        margin_m=margin,
        spread_m=default.spread_m if spread is None else spread,
        home_overhang_p=1.0 if overhang else default.home_overhang_p,
        random_home=random_home,
        anywhere=anywhere,
        **knobs,
    )
    return generate_hard_scene_with_info(seed=seed, options=options)
