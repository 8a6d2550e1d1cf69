"""Metric verification of a syntactic match: does the candidate's outline *lie on* the
target's, once turned and scaled, or does it only have the same sequence of corners?

The syntactic matcher (:mod:`uavtool.vision.recognize`) compares corners' turns and edges'
relative lengths, and forgives a great deal by design (corners merged, edges stretched): a
trapezoid whose top is 70 % of its base, a rectangle with one corner notched or an L with one
arm shorter all score like the target itself. Here the two outer outlines are put on each
other — centroids together, each scaled to unit area, the candidate turned by the match's
rotation (refined) and mirrored if the match was — and their largest distance apart is
measured (the symmetric Hausdorff distance).

How far apart two outlines of the *same* footprint may lie follows from how exactly each was
drawn: a vectorized outline lies within `outline_accuracy_px` of the true one in its own
photo's pixels (the pixel grid's half pixel and the simplification's tolerance). At unit
area, a photo whose shape covers ``A`` square pixels draws it to ``accuracy / sqrt(A)``: the
tolerance is the two photos' sum. Two footprints that differ by less than that cannot be
told apart in these photos — a closer look can; never a lower bar.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from uavtool.vision.align import Match
from uavtool.vision.params import VectorizeParams
from uavtool.vision.shapes import STAIRCASE_PX, FloatArray, Shape

__all__ = [
    "detail_differs",
    "hides_detail",
    "outline_accuracy_px",
    "outline_fits",
    "outline_gap",
    "outline_tolerance",
]

_REFINE_DEG = (4.0, 1.0, 0.25, 0.0625)  # the rotation searched around the match's, finer each pass
_DENSIFY = 0.02  # Hausdorff's densification: segments split into 2 % pieces


def outline_accuracy_px(params: VectorizeParams) -> float:
    """How far (pixels) a vectorized outline may lie from the true one, its size and turn
    aside. With ``refine_corners`` (the default) every corner is where lines fitted to its
    two edges meet: along an edge the pixel grid's error averages out, except along an edge
    that runs with the grid, whose every pixel is off by the same fraction. A corner between
    two such edges is known only to the pixel it falls in: half its diagonal, √2 / 2 px.
    Without ``refine_corners`` the corners are the simplification's points: half a pixel of
    grid and the simplification's tolerance.

    Measured (`benchmarks/bench_near_shapes.py --accuracy`: 3,000 rectangles, L, T and U
    shapes at any turn drawn by the renderer's pixel-centre rule, σ 3 DN of noise, put on
    the true outline at unit area), a vectorized outline lies a median 0.1 px from the true
    one; of outlines 100 px across or more, 99.6 % lie within √2 / 2 px. Under 100 px across,
    edges shorter than ``min_edge_px`` are lost and 1 outline in 20 lies further (a photo
    that draws the target so small is not judged, `uavtool.mission.analysis.judge`)."""
    if params.refine_corners:
        return math.sqrt(0.5)
    return 0.5 + params.rdp_epsilon_px


def outline_tolerance(
    reference: Shape,
    candidate: Shape,
    accuracy_px: float,
    reference_accuracy_px: float,
) -> float:
    """The largest gap (at unit area) two vectorized outlines of one footprint may show: each
    outline's accuracy in its own pixels, at its own scale. The reference outline, when it
    leaves out more of its traced border than that (``Shape.detail_px``: a step or notch
    shorter than an edge it keeps, the tiers of a building at several heights drawn a few
    pixels apart), is known only to what it left out; so is the candidate's, as far as the
    reference could not have drawn it either (one that left out more is not judged at all:
    `hides_detail`)."""
    ref_px = max(reference_accuracy_px, reference.detail_px)
    cand_px = max(accuracy_px, candidate.detail_px)
    return ref_px / math.sqrt(max(reference.area_px, 1.0)) + cand_px / math.sqrt(
        max(candidate.area_px, 1.0)
    )


LEGS_PER_DETAIL = 2.0
"""How long a feature an outline left out may be, per pixel of `Shape.detail_px` (see
`hides_detail`)."""


def hides_detail(reference: Shape, candidate: Shape, reference_min_edge_px: float) -> bool:
    """Whether ``candidate``'s outline leaves out (``Shape.detail_px``) a feature the
    reference's photo would have drawn as an edge of its outline: at least
    ``reference_min_edge_px`` long at the reference's scale (a notch or a cut corner this
    photo drew too small to keep, or a blurred outline a few pixels across). Whether such a
    candidate is the reference cannot be told from this photo: the feature may be what makes
    it another building. A closer photo draws it.

    The feature left out may be up to `LEGS_PER_DETAIL` times the detail long: a corner
    cut at 45° whose legs are ``c`` lies at most ``c / 2`` from the corner the outline
    kept, the most length for the least detail of any corner cut (a square notch of side
    ``k`` leaves out ``k``). A candidate drawn at least as large as the reference hides
    nothing from it: what its outline left out, the reference's, drawn smaller by the same
    vectorizer, leaves out too."""
    if candidate.detail_px <= 0.0:
        return False
    drawn = math.sqrt(max(candidate.area_px, 0.0))
    scale = math.sqrt(max(reference.area_px, 0.0))
    if drawn >= scale:
        return False
    return LEGS_PER_DETAIL * candidate.detail_px * scale >= reference_min_edge_px * drawn


def detail_differs(reference: Shape, candidate: Shape) -> bool:
    """Whether one photo's outline left out a feature (``Shape.left_out_px`` beyond the
    pixel grid's `STAIRCASE_PX`: a notch or a cut corner drawn under the least edge kept)
    that the other photo, were it of the same footprint, would draw and does not: the other
    left out nothing (its traced border lies within the staircase of its outline), and the
    feature, carried to its scale (the ratio of the two shapes' ``sqrt(area)``), would stand
    beyond its staircase. When both left something out they may have left out the same
    feature, drawn apart by each photo's perspective (a step between a building's tiers):
    its size then tells nothing."""
    scale = math.sqrt(max(reference.area_px, 0.0))
    drawn = math.sqrt(max(candidate.area_px, 0.0))
    if not (scale > 0.0 and drawn > 0.0):
        return False
    return _missing(candidate.left_out_px, reference.left_out_px, scale / drawn) or _missing(
        reference.left_out_px, candidate.left_out_px, drawn / scale
    )


def _missing(left_out_px: float, clean_px: float, ratio: float) -> bool:
    """Whether a feature of ``left_out_px`` (beyond the staircase) is missing from a photo
    whose outline left out ``clean_px`` (within its staircase), drawn ``ratio`` times as
    large there."""
    if clean_px > STAIRCASE_PX:
        return False
    return (left_out_px - STAIRCASE_PX) * ratio > clean_px + STAIRCASE_PX


def outline_fits(
    reference: Shape,
    candidate: Shape,
    match: Match,
    params: VectorizeParams | None = None,
    reference_params: VectorizeParams | None = None,
) -> bool:
    """Whether ``candidate`` (vectorized with ``params``) lies on ``reference`` (vectorized
    with ``reference_params``, by default the same) as closely as one footprint photographed
    twice can: `outline_gap` within `outline_tolerance`, nothing left out of it that
    the reference would show (`hides_detail`) and no feature one left out that the other
    does not (`detail_differs`)."""
    p = params if params is not None else VectorizeParams()
    q = reference_params if reference_params is not None else p
    if hides_detail(reference, candidate, q.min_edge_px) or detail_differs(reference, candidate):
        return False
    tolerance = outline_tolerance(
        reference, candidate, outline_accuracy_px(p), outline_accuracy_px(q)
    )
    return outline_gap(reference, candidate, match) <= tolerance


def outline_gap(reference: Shape, candidate: Shape, match: Match) -> float:
    """The symmetric Hausdorff distance between the two outer outlines at unit area, with
    centroids together and the candidate turned (mirrored if the match was) onto the
    reference as well as any turn near the match's allows; ``inf`` when either is
    degenerate."""
    return _laid(reference, candidate, match)[0]


def carried_point(
    reference: Shape, candidate: Shape, match: Match, point_px: tuple[float, float]
) -> tuple[float, float] | None:
    """Where ``point_px`` of the reference's photo falls in the candidate's: carried with
    the reference's outline onto the candidate's as `outline_gap` lays them together
    (centroids together, turned and, if the match was, mirrored, at the ratio of their
    sizes). None when either outline is degenerate."""
    gap, deg = _laid(reference, candidate, match)
    if not math.isfinite(gap):
        return None
    ref, cand = shapely.Polygon(reference.polygon_px), shapely.Polygon(candidate.polygon_px)
    unit = (np.array(point_px, dtype=np.float64) - ref.centroid.coords[0]) / math.sqrt(ref.area)
    t = math.radians(deg)
    c, s = math.cos(t), math.sin(t)
    # the candidate, turned by ``deg`` (`_gap`), lies on the reference: turn back
    there = unit @ np.array([[c, s], [-s, c]]).T
    if match.mirrored:
        there = there * np.array([-1.0, 1.0])
    u, v = np.asarray(cand.centroid.coords[0]) + math.sqrt(cand.area) * there
    return float(u), float(v)


def _laid(reference: Shape, candidate: Shape, match: Match) -> tuple[float, float]:
    """`outline_gap` and the turn (degrees, `_gap`'s) that gives it."""
    ref = _unit(reference.polygon_px)
    cand = _unit(candidate.polygon_px)
    if ref is None or cand is None:
        return math.inf, 0.0
    if match.mirrored:
        cand = cand * np.array([-1.0, 1.0])
    ref_line = shapely.LinearRing(ref)
    best_deg, best = 0.0, math.inf
    # the match's rotation turns the reference into the candidate: undo it; which sense the
    # angle is counted in is settled by trying both
    for start in (-match.rotation_deg, match.rotation_deg):
        gap = _gap(ref_line, cand, start)
        if gap < best:
            best_deg, best = start, gap
    for step in _REFINE_DEG:
        centre = best_deg
        for k in (-2, -1, 1, 2):
            deg = centre + k * step
            gap = _gap(ref_line, cand, deg)
            if gap < best:
                best_deg, best = deg, gap
    return best, best_deg


def _gap(ref_line: shapely.LinearRing, cand: FloatArray, deg: float) -> float:
    t = math.radians(deg)
    c, s = math.cos(t), math.sin(t)
    turned = cand @ np.array([[c, s], [-s, c]])
    return float(shapely.hausdorff_distance(ref_line, shapely.LinearRing(turned), _DENSIFY))


def _unit(ring: FloatArray) -> FloatArray | None:
    """``ring`` with its area centroid at the origin and its area 1."""
    pts = np.asarray(ring, dtype=np.float64)
    if len(pts) < 3:
        return None
    polygon = shapely.Polygon(pts)
    area = polygon.area
    if not area > 0.0:
        return None
    c = polygon.centroid
    unit: FloatArray = (pts - (c.x, c.y)) / math.sqrt(area)
    return unit
