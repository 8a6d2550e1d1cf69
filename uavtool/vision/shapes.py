"""The vector shape: what vectorization produces and recognition and model building consume."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from uavtool.camera import Intrinsics

FloatArray = npt.NDArray[np.float64]

STAIRCASE_PX = 1.0
"""How far a traced border may stray from a straight edge by the pixel grid alone: the
staircase of a slanted edge, a pixel at most. What an outline leaves out beyond it
(``Shape.left_out_px``) is a feature of the footprint (a notch, a cut corner, a step) drawn
too small to keep as an edge."""


@dataclass(frozen=True, slots=True)
class Shape:
    """One coloured region of a frame as polygons in pixel coordinates (OpenCV convention).

    ``polygon_px`` : (n, 2) float — the outer ring, oriented so :func:`signed_area` is
    positive (clockwise as seen on screen, where y points down), without repeating the
    first vertex at the end.
    ``holes_px`` : tuple of (m, 2) float — inner rings (a courtyard seen from above),
    oriented the other way (negative signed area).
    ``area_px`` : outer area minus hole areas, in square pixels.
    ``centroid_px`` : area centroid ``(u, v)`` of the region with holes removed.
    ``cut_by_border`` : the region touches the image border, so its outline is incomplete.
    ``detail_px`` : how far the traced border strays from ``polygon_px`` at most, in pixels:
    what the simplification left out (a step or notch shorter than an edge it keeps); 0
    when the shape was not traced from pixels.
    ``left_out_px`` : the part of ``detail_px`` the outline left out, as against a step it
    kept at the limit of what it keeps (an edge shorter than ``min_edge_px``): how far the
    traced border strays from ``polygon_px`` at most.
    """

    colour_rgb: tuple[int, int, int]
    polygon_px: FloatArray
    holes_px: tuple[FloatArray, ...]
    area_px: float
    centroid_px: tuple[float, float]
    cut_by_border: bool
    detail_px: float = 0.0
    left_out_px: float = 0.0

    @classmethod
    def from_rings(
        cls,
        *,
        colour_rgb: tuple[int, int, int],
        polygon_px: FloatArray,
        holes_px: tuple[FloatArray, ...] = (),
        cut_by_border: bool = False,
        detail_px: float = 0.0,
        left_out_px: float = 0.0,
    ) -> Shape:
        """A shape whose orientation, area and centroid are computed from its rings."""
        outer = orient(np.asarray(polygon_px, dtype=np.float64), positive=True)
        holes = tuple(orient(np.asarray(h, dtype=np.float64), positive=False) for h in holes_px)
        rings = (outer, *holes)
        area, cu, cv = _area_moments(rings)
        centroid = (cu / area, cv / area) if area != 0.0 else _vertex_mean(outer)
        return cls(colour_rgb, outer, holes, area, centroid, cut_by_border, detail_px, left_out_px)


def signed_area(ring: FloatArray) -> float:
    """Shoelace area of a closed ring ``(n, 2)``; positive when the ring turns counter-clockwise
    in a y-up frame (clockwise as seen on screen, y down). Summed with ``math.fsum`` so the
    result does not depend on array layout."""
    pts = ring.tolist()
    return 0.5 * math.fsum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True)
    )


def orient(ring: FloatArray, *, positive: bool) -> FloatArray:
    """The ring with its vertex order reversed if needed so ``signed_area`` has the given sign."""
    if (signed_area(ring) > 0.0) != positive:
        return ring[::-1].copy()
    return ring


def _area_moments(rings: tuple[FloatArray, ...]) -> tuple[float, float, float]:
    # Plain float arithmetic: outlines have tens of vertices, where numpy's per-call cost
    # dominates; each term is the same IEEE operation either way.
    area_terms: list[float] = []
    mu_terms: list[float] = []
    mv_terms: list[float] = []
    for ring in rings:
        pts = ring.tolist()
        for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True):
            cross = x0 * y1 - x1 * y0
            area_terms.append(cross)
            mu_terms.append((x0 + x1) * cross)
            mv_terms.append((y0 + y1) * cross)
    area = 0.5 * math.fsum(area_terms)
    return area, math.fsum(mu_terms) / 6.0, math.fsum(mv_terms) / 6.0


def _vertex_mean(ring: FloatArray) -> tuple[float, float]:
    n = len(ring)
    return (math.fsum(ring[:, 0].tolist()) / n, math.fsum(ring[:, 1].tolist()) / n)


def perimeter(ring: FloatArray) -> float:
    """Length of a closed ring ``(n, 2)``, summed in a fixed order."""
    d = np.concatenate([ring[1:], ring[:1]]) - ring
    return math.fsum(np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]).tolist())


EDGE_PX = 1.0  # an outline this close to the frame's edge touches it


def cut_edges(silhouette: Sequence[Shape], k: Intrinsics) -> set[str]:
    """Which edges of the frame (``top``, ``bottom``, ``left``, ``right``) the silhouette's
    outlines touch."""
    edges: set[str] = set()
    for shape in silhouette:
        if not shape.cut_by_border:
            continue
        us, vs = shape.polygon_px[:, 0], shape.polygon_px[:, 1]
        for edge, touches in (
            ("left", float(us.min()) <= EDGE_PX),
            ("right", float(us.max()) >= k.width_px - 1 - EDGE_PX),
            ("top", float(vs.min()) <= EDGE_PX),
            ("bottom", float(vs.max()) >= k.height_px - 1 - EDGE_PX),
        ):
            if touches:
                edges.add(edge)
    return edges
