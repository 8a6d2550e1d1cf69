"""One typed, documented parameter structure per vision stage.

Defaults are tuned on frames of the built-in scenes (640×480, 60° HFOV, 20–45 m altitude);
every field can be overridden, e.g. ``replace(VectorizeParams(), rdp_epsilon_px=3.0)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from types import MappingProxyType
from typing import ClassVar

from uavtool.checks import DN, FRACTION, NON_NEGATIVE, POSITIVE, Range, check_fields
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
    """Keep only the roofs, without the walls perspective shows around them (use for photos
    from above): each region's shade on its edges facing away from the photo's nadir, where
    a roof's edge is whatever the light (`uavtool.vision.roof`)."""
    roof_value_tolerance: int = 20
    """With ``roof_only``, the furthest an HSV value (0–255) may lie from the roof's shade
    and count as roof. Within it, what counts is the roof's own spread (its noise, measured
    on its edges: :func:`uavtool.vision.roof.roof_tolerance`); a wall lit within that of
    its roof is taken with it."""
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

    RANGES: ClassVar[Mapping[str, Range]] = MappingProxyType(
        {
            "palette_rgb": DN,
            "hue_tolerance_deg": Range(0.0, 90.0, lo_open=True),
            "min_saturation": DN,
            "min_value": DN,
            "denoise_px": Range(0, 255),
            "roof_value_tolerance": DN,
            "point_spacing_px": POSITIVE,
            "rdp_epsilon_px": NON_NEGATIVE,
            "min_edge_px": POSITIVE,
            "straight_tolerance_px": NON_NEGATIVE,
            "min_area_px": POSITIVE,
            "min_hole_area_px": NON_NEGATIVE,
            "edge_offset_px": NON_NEGATIVE,
        }
    )
    """Allowed values of each field (floats must also be finite)."""

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="vectorize", error=VisionParamError)
        if self.denoise_px > 1 and self.denoise_px % 2 == 0:
            raise VisionParamError(
                f"vectorize.denoise_px must be 0, 1 or odd, got {self.denoise_px}"
            )


@dataclass(frozen=True, slots=True)
class RecognizeParams:
    """Parameters of :func:`uavtool.vision.recognize.match`.

    Each corner is a symbol (turning angle, length of the following edge relative to the
    perimeter). A matched pair of symbols costs ``|Δangle| / angle_scale_deg + |Δlength| ·
    n / length_scale`` (``n`` the mean corner count, so a length error is relative to the
    mean edge); merging ``k`` consecutive corners of one outline into one corner of the other
    (a corner that simplification split, an extra vertex on a straight edge, a step in an
    edge) costs ``merge_cost`` for each dropped corner plus how far it stands off the
    straight edge that replaces it, relative to the perimeter as lengths are. The score is
    ``1 − total / n`` clipped to [0, 1].
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
    then only refuses a candidate clearly more like the mirror image. The mission takes it
    too as how far two buildings' scores may differ by noise alone: within it, the openings
    inside their outlines decide."""

    RANGES: ClassVar[Mapping[str, Range]] = MappingProxyType(
        {
            "angle_scale_deg": POSITIVE,
            "length_scale": POSITIVE,
            "merge_cost": NON_NEGATIVE,
            "max_merge": Range(1, 100),
            "hole_penalty": NON_NEGATIVE,
            "threshold": FRACTION,
            "mirror_margin": NON_NEGATIVE,
            "mirror_tolerance": NON_NEGATIVE,
        }
    )
    """Allowed values of each field (floats must also be finite)."""

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="recognize", error=VisionParamError)


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

    RANGES: ClassVar[Mapping[str, Range]] = MappingProxyType(
        {
            "max_iterations": Range(1, 10_000),
            "tolerance_m": POSITIVE,
            "max_top_tilt_deg": Range(0.0, 90.0, lo_open=True),
            "max_side_tilt_deg": Range(0.0, 90.0, lo_open=True),
            "min_view_separation_deg": Range(0.0, 180.0),
        }
    )
    """Allowed values of each field (floats must also be finite)."""

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="model", error=VisionParamError)


def field_names(cls: type) -> tuple[str, ...]:
    """Names of a parameter structure's fields (for ``--set``-style overrides)."""
    return tuple(f.name for f in fields(cls))
