"""``uavtool vision``: vectorize a frame, match a target, build a 3D model from three photos."""

from __future__ import annotations

from pathlib import Path

import click

from uavtool.cli.options import Number
from uavtool.cli.spelling import Command, OldSpelling
from uavtool.errors import FailureError

_IMAGE = click.Path(path_type=Path)  # read (and checked) by uavtool.images
_OUT = click.Path(dir_okay=False, writable=True, path_type=Path)
_OLD_SPELLINGS = (OldSpelling("--out", "--output", "-o/--output"),)


@click.group()
def vision() -> None:
    """Vectorize frames, recognize a target shape, build a 3D model (paper section III).

    \b
    Example:
      uavtool vision vectorize frame.png -o shapes.json --overlay overlay.png
    """


@vision.command("vectorize", cls=Command, old_spellings=_OLD_SPELLINGS)
@click.argument("frame", type=_IMAGE)
@click.option("-o", "--output", "out", type=_OUT, help="Write the shapes as JSON here.")
@click.option("--overlay", type=_OUT, help="Write the frame with the vectors drawn over it (PNG).")
@click.option(
    "--epsilon",
    type=Number(),
    default=None,
    help="RDP tolerance in pixels (default 1.5).",
)
@click.option(
    "--spacing",
    type=Number(),
    default=None,
    help="Border point spacing in pixels (default 2).",
)
def vectorize_cmd(
    frame: Path,
    out: Path | None,
    overlay: Path | None,
    epsilon: float | None,
    spacing: float | None,
) -> None:
    """Find the coloured shapes of FRAME and print one line per shape.

    Every saturated colour cluster becomes shapes (grey ground and pale sky do not); each
    shape keeps the colour of a pixel inside it, its corners, holes, area and centroid.
    The overlay draws outlines (magenta when cut by the image border), holes (cyan) and
    corner points over the frame, enlarged twice.

    \b
    Example:
      uavtool vision vectorize frame.png -o shapes.json --overlay overlay.png
    """
    from dataclasses import replace

    from uavtool.vision.commands import vectorize_file
    from uavtool.vision.params import VectorizeParams

    params = VectorizeParams()
    if epsilon is not None:
        params = replace(params, rdp_epsilon_px=epsilon)
    if spacing is not None:
        params = replace(params, point_spacing_px=spacing)
    shapes = vectorize_file(frame, out=out, overlay=overlay, params=params)
    for i, s in enumerate(shapes):
        r, g, b = s.colour_rgb
        flags = " cut-by-border" if s.cut_by_border else ""
        click.echo(
            f"{i:3d}  rgb({r:3d},{g:3d},{b:3d})  {len(s.polygon_px):3d} corners  "
            f"{len(s.holes_px)} holes  area {s.area_px:9.1f} px  "
            f"centre ({s.centroid_px[0]:6.1f}, {s.centroid_px[1]:6.1f}){flags}"
        )
    click.echo(f"{len(shapes)} shapes")


@vision.command("match")
@click.argument("target", type=_IMAGE)
@click.argument("frame", type=_IMAGE)
@click.option(
    "--threshold",
    type=Number(),
    default=None,
    help="Match score threshold (default 0.8).",
)
@click.option("--allow-mirror", is_flag=True, help="Let a mirror image of the target match.")
def match_cmd(target: Path, frame: Path, threshold: float | None, allow_mirror: bool) -> None:
    """Score every shape of FRAME against the target bitmap TARGET (a picture from above).

    Prints each shape's score (0–1), rotation and scale relative to the target and whether
    it can be judged (a shape cut by the image border cannot: part of its outline is
    missing), then the best judgeable one. Exits with status 1 when no judgeable shape
    reaches the threshold, saying so when the best-scoring shape is cut.

    \b
    Example:
      uavtool vision match target.png frame.png
    """
    from dataclasses import replace

    from uavtool.vision.commands import match_files
    from uavtool.vision.params import RecognizeParams

    params = replace(RecognizeParams(), allow_mirror=allow_mirror)
    if threshold is not None:
        params = replace(params, threshold=threshold)
    report = match_files(target, frame, params=params)
    click.echo(f"target: {len(report.target.polygon_px)} corners, rgb{report.target.colour_rgb}")
    for i, (s, m) in enumerate(zip(report.shapes, report.matches, strict=True)):
        mark = "*" if i == report.best and report.matched else " "
        judged = "judgeable" if m.judgeable else "NOT judgeable (cut by the image border)"
        click.echo(
            f"{mark}{i:3d}  rgb{s.colour_rgb!s:15s} score {m.score:5.3f}  "
            f"rotation {m.rotation_deg:7.1f}°  scale {m.scale:5.2f}  {judged}"
            + ("  mirrored" if m.mirrored else "")
        )
    if not report.matched:
        raise FailureError(f"{frame}: {report.summary()}")
    click.echo(report.summary())


@vision.command("model", cls=Command, old_spellings=_OLD_SPELLINGS)
@click.argument("photos", nargs=-1, required=True, type=_IMAGE, metavar="TOP FRONT RIGHT | FOLDER")
@click.option(
    "--poses",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="JSON file with each photo's camera pose and intrinsics (its format is above); "
    "without it, each photo's .json sidecar beside it.",
)
@click.option("-o", "--output", "out", type=_OUT, required=True, help="Write the model here (GLB).")
def model_cmd(photos: tuple[Path, ...], poses: Path | None, out: Path) -> None:
    """Build the 3D model of the building in TOP, FRONT and RIGHT photos; write a GLB.

    The building is the shape the TOP photo (gimbal near nadir) is centred on; in FRONT and
    RIGHT (gimbal near horizontal, headings ~90° apart) every shape of its colour counts.

    Each photo's camera comes from the .json sidecar beside it (frame_0006.png beside
    frame_0006.json, as `uavtool export --frames` writes them), or from a poses file. Given a
    FOLDER that `export --frames` wrote, the photos are the frames tagged top, front and right.

    \b
    The poses file gives each photo's camera in local ENU metres around home:
      {"top":   {"pos_enu_m": [10, -8, 20], "heading_deg": 0, "pitch_deg": -90,
                 "intrinsics": {"width_px": 640, "height_px": 480, "hfov_deg": 60}},
       "front": {"pos_enu_m": [10, -27, 3], "heading_deg": 0, "pitch_deg": 0,
                 "intrinsics": {...}},
       "right": {"pos_enu_m": [30, -8, 3], "heading_deg": 270, "pitch_deg": 0,
                 "intrinsics": {...}},
       "ground_z_m": 0}
    heading_deg is the camera's heading (clockwise from north), pitch_deg the gimbal
    pitch (-90 = straight down); intrinsics take hfov_deg or fx_px, fy_px, cx_px, cy_px.

    \b
    Examples:
      uavtool export flight.mcap --frames f/ && uavtool vision model f/ -o model.glb
      uavtool vision model f/frame_0006.png f/frame_0007.png f/frame_0008.png -o model.glb
      uavtool vision model top.png front.png right.png --poses poses.json -o model.glb
    """
    if len(photos) == 1 and photos[0].is_dir():
        from uavtool.vision.sidecars import views_in_folder

        if poses is not None:
            raise click.UsageError("a FOLDER's frames carry their poses: drop --poses")
        top, front, right = views_in_folder(photos[0]).values()
    elif len(photos) == 3:
        top, front, right = photos
    else:
        raise click.UsageError(
            f"give three photos (TOP FRONT RIGHT) or one folder of uavtool export --frames, "
            f"not {len(photos)}"
        )
    from uavtool.vision.commands import model_files

    model = model_files(top, front, right, poses=poses, out=out)
    lo, hi = model.mesh.bounds
    click.echo(
        f"model: {len(model.mesh.faces)} triangles, volume {model.mesh.volume:.1f} m³, "
        f"height {model.height_m:.2f} m, size {hi[0] - lo[0]:.2f} x {hi[1] - lo[1]:.2f} m "
        f"(east x north), watertight {model.mesh.is_watertight}"
    )
    click.echo(f"wrote {out}")
