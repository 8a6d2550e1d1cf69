"""One typed, documented parameter structure per vision stage.

Defaults are tuned on frames of the built-in scenes (640×480, 60° HFOV, 20–45 m altitude);
every field can be overridden, e.g. ``replace(VectorizeParams(), rdp_epsilon_px=3.0)``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from uavtool.vision.errors import VisionParamError


@dataclass(frozen=True, slots=True)
class VectorizeParams:
    """Parameters of :func:`uavtool.vision.vectorize.vectorize`.

    Palette: when ``palette_rgb`` is empty the palette is found in the frame: every hue
    cluster of saturated pixels (a peak of the hue histogram holding at least
    ``min_area_px`` pixels) becomes one colour. Ground (neutral grey) and sky (pale) are
    below ``min_saturation`` and never form shapes. When ``palette_rgb`` lists colours, only
    those are extracted, each as the hues within ``hue_tolerance_deg`` of it — this is how the
    mission isolates the target's colour in the front and right photos.
    """

    palette_rgb: tuple[tuple[int, int, int], ...] = ()
    """Colours to extract; empty = auto-detect hue clusters."""
    hue_tolerance_deg: float = 12.0
    """Half-width of the hue window around a palette colour, degrees (0–360 hue circle)."""
    min_saturation: int = 70
    """HSV saturation (0–255) below which a pixel is background (grey ground, pale sky)."""
    min_value: int = 30
    """HSV value (0–255) below which a pixel is too dark to trust its hue."""
    denoise_px: int = 3
    """Median filter aperture applied to the colour-class image (0 or 1 = off; odd)."""
    roof_only: bool = False
    """Keep only the brightest shade of each colour: in a photo from above that is the
    roofs, without the walls perspective shows around them (use for nadir photos)."""
    roof_value_tolerance: int = 20
    """With ``roof_only``, HSV values (0–255) this far below the brightest shade still count
    as roof (sensor noise); walls are darker by much more under the renderer's lighting."""
    point_spacing_px: float = 2.0
    """Distance between the evenly spaced points put along each border: larger is faster
    and coarser."""
    rdp_epsilon_px: float = 1.5
    """Ramer–Douglas–Peucker tolerance: the simplified outline stays within this distance of
    the evenly spaced points."""
    refine_corners: bool = True
    """Move each corner to the intersection of lines fitted to its two edges, and merge the
    two halves of a corner the evenly spaced points straddled."""
    min_edge_px: float = 8.0
    """With ``refine_corners``, edges shorter than this are the stub of a split or rounded
    corner: they are dropped and the corner put where the neighbouring edges meet."""
    straight_tolerance_px: float = 1.0
    """With ``refine_corners``, two neighbouring edges up to ~15° apart whose points all lie
    within this of one fitted line are one edge (a straight edge rasterises as runs whose
    short pieces look a few degrees off); 0 = only edges within ~3° are joined."""
    min_area_px: float = 60.0
    """Regions (and hue clusters) smaller than this many pixels are dropped as noise."""
    min_hole_area_px: float = 30.0
    """Holes smaller than this many pixels are filled (noise inside a roof)."""
    edge_offset_px: float = 0.5
    """Outlines follow the centres of the border pixels; each edge is then moved outward by
    this much so the polygon follows the pixel edges and its area matches the pixel count."""

    def __post_init__(self) -> None:
        _check_positive(self, "point_spacing_px", "min_area_px", "min_edge_px")
        _check_non_negative(
            self, "rdp_epsilon_px", "min_hole_area_px", "edge_offset_px", "straight_tolerance_px"
        )
        if not 0.0 < self.hue_tolerance_deg <= 90.0:
            raise VisionParamError(
                f"vision.hue_tolerance_deg must be in (0, 90], got {self.hue_tolerance_deg}"
            )
        if not 0 <= self.min_saturation <= 255 or not 0 <= self.min_value <= 255:
            raise VisionParamError("vision.min_saturation and vision.min_value must be in [0, 255]")
        if self.denoise_px < 0 or (self.denoise_px > 1 and self.denoise_px % 2 == 0):
            raise VisionParamError(f"vision.denoise_px must be 0 or odd, got {self.denoise_px}")
        for colour in self.palette_rgb:
            if len(colour) != 3 or not all(0 <= c <= 255 for c in colour):
                raise VisionParamError(f"vision.palette_rgb: {colour} is not an RGB triple 0–255")


@dataclass(frozen=True, slots=True)
class RecognizeParams:
    """Parameters of :func:`uavtool.vision.recognize.match`.

    Each corner is a symbol (turning angle, length of the following edge relative to the
    perimeter). A matched pair of symbols costs ``|Δangle| / angle_scale_deg + |Δlength| ·
    n / length_scale`` (``n`` the mean corner count, so a length error is relative to the
    mean edge); merging ``k`` consecutive corners of one outline into one corner of the other
    (a corner that simplification split, or an extra vertex on a straight edge) costs
    ``merge_cost`` each plus the smaller of the dropped turn and the dropped edge, in the
    same units. The score is ``1 − total / n`` clipped to [0, 1].
    """

    angle_scale_deg: float = 90.0
    """A turning-angle error of this many degrees costs 1."""
    length_scale: float = 1.0
    """A relative edge-length error of one mean edge costs this inverse."""
    merge_cost: float = 0.15
    """Base cost of merging two corners into one."""
    max_merge: int = 3
    """At most this many consecutive corners merge into one."""
    hole_penalty: float = 0.25
    """Subtracted from the score per differing number of holes."""
    threshold: float = 0.8
    """Scores at or above this are a match."""
    allow_mirror: bool = False
    """Also try the mirror image (a mirrored building is a different building by default)."""
    mirror_margin: float = 0.25
    """The mirror rule (used by the mission's decision): a candidate is the reference and not
    its mirror image only if its score beats its score against the reference's mirror image
    by this fraction of the reference's chirality gap (1 − the reference's score against its
    own mirror image). The true building then wins by about the whole gap, its mirror image
    loses by it."""
    mirror_tolerance: float = 0.01
    """… less this: how far an outline's score and its mirror image's may differ by pixel
    noise alone. For a reference that is its own mirror image (a rectangle, a T) the rule
    then only refuses a candidate clearly more like the mirror image."""

    def __post_init__(self) -> None:
        _check_positive(self, "angle_scale_deg", "length_scale")
        _check_non_negative(self, "merge_cost", "hole_penalty", "mirror_margin", "mirror_tolerance")
        if self.max_merge < 1:
            raise VisionParamError(f"vision.max_merge must be ≥ 1, got {self.max_merge}")
        if not 0.0 <= self.threshold <= 1.0:
            raise VisionParamError(f"vision.threshold must be in [0, 1], got {self.threshold}")


@dataclass(frozen=True, slots=True)
class ModelParams:
    """Parameters of :func:`uavtool.vision.model3d.build_model`."""

    ground_z_m: float = 0.0
    """Height of the ground the building stands on (ENU z)."""
    max_iterations: int = 20
    """Fixed-point iterations for the roof height (footprint and wall distances depend on it)."""
    tolerance_m: float = 1e-6
    """Stop iterating when the roof height changes less than this."""
    max_top_tilt_deg: float = 30.0
    """The top photo's gimbal pitch must be within this of nadir (−90°)."""
    max_side_tilt_deg: float = 45.0
    """The front and right photos' gimbal pitch must be within this of horizontal."""
    min_view_separation_deg: float = 30.0
    """The front and right headings must differ by at least this (ideally 90°)."""
    allow_border_cut: bool = False
    """Accept silhouettes that touch the image border (the model is then truncated)."""

    def __post_init__(self) -> None:
        _check_positive(self, "tolerance_m", "max_top_tilt_deg", "max_side_tilt_deg")
        if self.max_iterations < 1:
            raise VisionParamError(f"vision.max_iterations must be ≥ 1, got {self.max_iterations}")


def _check_positive(obj: object, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not value > 0:
            raise VisionParamError(f"vision.{name} must be positive, got {value}")


def _check_non_negative(obj: object, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not value >= 0:
            raise VisionParamError(f"vision.{name} must be ≥ 0, got {value}")


def field_names(cls: type) -> tuple[str, ...]:
    """Names of a parameter structure's fields (for ``--set``-style overrides)."""
    return tuple(f.name for f in fields(cls))
