"""File-level vision tasks behind ``uavtool vision``: read images, run one stage, write files.

The stages themselves stay pure; this module is the thin I/O shell the CLI calls.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2

from uavtool.camera import Intrinsics
from uavtool.fifo import reader_held
from uavtool.images import read_image
from uavtool.vision.errors import ImageError, ModelInputError, ShapeFileError
from uavtool.vision.io import shapes_to_json, views_from_json
from uavtool.vision.model3d import Model, View, build_model, central_shape, model_glb, same_colour
from uavtool.vision.overlay import draw_overlay
from uavtool.vision.params import ModelParams, RecognizeParams, VectorizeParams
from uavtool.vision.recognize import Match, best_match
from uavtool.vision.shapes import Shape
from uavtool.vision.sidecars import poses_from_sidecars
from uavtool.vision.vectorize import U8Array, vectorize


def write_image(path: Path, rgb: U8Array) -> None:
    """Write an RGB image (format from the file extension)."""
    try:
        with reader_held(path):
            ok = cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    except cv2.error:  # no encoder for the extension
        ok = False
    if not ok:
        raise ImageError(f"{path}: cannot write an image there (check the extension)")


def _write(path: Path, data: str | bytes) -> None:
    try:
        with reader_held(path):
            if isinstance(data, str):
                path.write_text(data)
            else:
                path.write_bytes(data)
    except OSError as exc:
        raise ImageError(f"{path}: cannot write: {exc.strerror or exc}") from None


def vectorize_file(
    frame: Path,
    *,
    out: Path | None,
    overlay: Path | None,
    params: VectorizeParams | None = None,
) -> tuple[Shape, ...]:
    """Vectorize an image file; write the shapes JSON and the overlay PNG when asked."""
    rgb = read_image(frame)
    shapes = vectorize(rgb, params)
    if out is not None:
        _write(out, shapes_to_json(shapes, width_px=rgb.shape[1], height_px=rgb.shape[0]))
    if overlay is not None:
        write_image(overlay, draw_overlay(rgb, shapes))
    return shapes


@dataclass(frozen=True, slots=True)
class MatchReport:
    """The target's shape, every shape of the frame with its match, and ``best``: the best
    judgeable shape's index (−1 if none; a shape cut by the image border is not judged)."""

    target: Shape
    shapes: tuple[Shape, ...]
    matches: tuple[Match, ...]
    best: int
    threshold: float

    @property
    def matched(self) -> bool:
        """Whether the best judgeable shape reaches the threshold."""
        return self.best >= 0 and self.matches[self.best].score >= self.threshold

    @property
    def top(self) -> int:
        """The highest-scoring shape, judgeable or not (−1 when the frame has none)."""
        if not self.matches:
            return -1
        return max(range(len(self.matches)), key=lambda i: (self.matches[i].score, -i))

    def summary(self) -> str:
        """One line: the match, or why there is none (no shape, a cut best, a low score)."""
        if self.matched:
            return f"best: shape {self.best}, score {self.matches[self.best].score:.3f}"
        top = self.top
        if top < 0:
            why = "the frame has no coloured shape"
        elif not self.matches[top].judgeable:
            why = (
                f"the best-scoring shape {top} ({self.matches[top].score:.3f}) is not "
                "judgeable: its outline is cut by the image border"
            )
        else:
            why = f"the best, shape {top}, scores {self.matches[top].score:.3f}"
        return f"no shape matches the target (threshold {self.threshold:g}): {why}"


def match_files(
    target: Path,
    frame: Path,
    *,
    vectorize_params: VectorizeParams | None = None,
    params: RecognizeParams | None = None,
) -> MatchReport:
    """Vectorize the target bitmap (its largest shape is the target) and a frame, and match
    every shape of the frame against the target."""
    p = params if params is not None else RecognizeParams()
    # Both pictures are taken from above: compare roofs, not the walls perspective shows.
    vp = vectorize_params if vectorize_params is not None else VectorizeParams(roof_only=True)
    target_shapes = vectorize(read_image(target), vp)
    if not target_shapes:
        raise ImageError(f"{target}: no coloured shape found in the target image")
    reference = max(target_shapes, key=lambda s: s.area_px)
    shapes = vectorize(read_image(frame), vp)
    best, matches = best_match(reference, shapes, p)
    return MatchReport(reference, shapes, matches, best, p.threshold)


def model_files(
    top: Path,
    front: Path,
    right: Path,
    *,
    poses: Path | None,
    out: Path,
    vectorize_params: VectorizeParams | None = None,
    params: ModelParams | None = None,
    hue_tolerance_deg: float = 15.0,
) -> Model:
    """Build the model from three photos and their poses file (None: each photo's sidecar,
    ``NAME.json`` beside ``NAME.png``, as ``uavtool export --frames`` writes them); write it as
    GLB.

    The object is the shape the top photo is centred on (its roofs only); in the front and
    right photos, every shape of its colour is the object.
    """
    images = {"top": top, "front": front, "right": right}
    if poses is None:  # each photo's sidecar, as uavtool export --frames writes them
        text, source = poses_from_sidecars(images), f"{top.parent}/<sidecars>"
    else:
        try:
            text = poses.read_text(encoding="utf-8")
        except OSError as exc:
            raise ShapeFileError(f"{poses}: cannot read: {exc.strerror or exc}") from None
        except UnicodeDecodeError:
            raise ShapeFileError(f"{poses}: not a JSON text file") from None
        source = str(poses)
    cams, ground = views_from_json(text, source=source)
    shapes: dict[str, tuple[Shape, ...]] = {}
    for name, path in images.items():
        rgb = read_image(path)
        _check_size(path, rgb, cams[name][1])
        vp = vectorize_params or VectorizeParams(roof_only=name == "top")
        shapes[name] = vectorize(rgb, vp)
    obj = central_shape(shapes["top"], cams["top"][1])
    if obj is None:
        raise ModelInputError(f"{top}: no coloured shape in the top photo")
    views = {
        name: View(
            (obj,)
            if name == "top"
            else same_colour(shapes[name], obj.colour_rgb, hue_tolerance_deg=hue_tolerance_deg),
            cams[name][0],
            cams[name][1],
        )
        for name in images
    }
    p = params if params is not None else ModelParams(ground_z_m=ground)
    model = build_model(views["top"], views["front"], views["right"], p)
    _write(out, model_glb(model))
    return model


def _check_size(path: Path, rgb: U8Array, k: Intrinsics) -> None:
    h, w = rgb.shape[:2]
    if (w, h) != (k.width_px, k.height_px):
        raise ImageError(
            f"{path}: image is {w}x{h} but its intrinsics say {k.width_px}x{k.height_px}"
        )
