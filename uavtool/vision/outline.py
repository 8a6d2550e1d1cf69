"""From traced pixel borders to polygon rings (paper III-A, steps 3 and 4).

Evenly spaced points along each border, Ramer–Douglas–Peucker, then corner refinement; all
the rings of a frame go through RDP and the line fits together. IEEE float64 arithmetic in
a fixed order, so the same borders give the same rings on every machine.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from uavtool.vision.corners import refine_rings
from uavtool.vision.params import VectorizeParams
from uavtool.vision.rdp import rdp_rings_indices
from uavtool.vision.shapes import FloatArray

# Mitre joins of the edge offset are clamped to this many offsets (spikes at sharp turns).
_MAX_MITRE = 3.0


def simplify_rings_detail(
    contours_px: list[npt.NDArray[Any]], p: VectorizeParams
) -> tuple[list[FloatArray], list[float], list[float]]:
    """Each closed pixel border ``(n, 2)`` as a simplified ring ``(m, 2)`` (``m`` may be < 3
    for a border too small to make a polygon); how much detail each ring holds at the limit
    of what it can be trusted with, in pixels: how far its border strays from it
    (:func:`ring_detail`: what the simplification left out), or its longest edge shorter
    than ``min_edge_px`` when longer (a step kept at the limit), whichever is more; and the
    first of those alone (what was left out)."""
    dense = [resample_ring(c.astype(np.float64), p.point_spacing_px) for c in contours_px]
    kept = rdp_rings_indices(dense, p.rdp_epsilon_px)
    if not p.refine_corners:
        rings = [d[k] for d, k in zip(dense, kept, strict=True)]
    else:
        rings = refine_rings(
            dense,
            [k.tolist() for k in kept],
            min_edge_px=p.min_edge_px,
            max_shift_px=p.min_edge_px + p.point_spacing_px + p.rdp_epsilon_px,
            straight_tolerance_px=p.straight_tolerance_px,
            # a vertex RDP kept on a short straight edge lies within its epsilon and a
            # pixel's half-diagonal of it
            join_tolerance_px=p.rdp_epsilon_px + math.sqrt(0.5),
        )
    left_out = [ring_detail(d, r) for d, r in zip(dense, rings, strict=True)]
    details = [
        max(gone, longest_stub(r, p.min_edge_px)) for gone, r in zip(left_out, rings, strict=True)
    ]
    return rings, details, left_out


def longest_stub(ring_px: FloatArray, min_edge_px: float) -> float:
    """The longest edge of ``ring_px`` shorter than ``min_edge_px`` (0 if none): a step the
    outline kept at the limit of what it keeps, which another photo may draw as a slant or
    not at all."""
    if len(ring_px) < 3:
        return 0.0
    d = np.roll(ring_px, -1, axis=0) - ring_px
    lengths = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])
    short = lengths[lengths < min_edge_px]
    return float(short.max()) if len(short) else 0.0


def ring_detail(points_px: FloatArray, ring_px: FloatArray) -> float:
    """The largest distance (pixels) from any of ``points_px`` ``(n, 2)`` to the closed ring
    ``ring_px`` ``(m, 2)``: how much of a traced border its simplified outline leaves out
    (a step or a notch shorter than an edge the outline keeps). 0 for fewer than 2 ring
    points."""
    if len(ring_px) < 2 or len(points_px) == 0:
        return 0.0
    a = ring_px[:, None, :]  # (m, 1, 2): each segment's start
    ab = np.roll(ring_px, -1, axis=0)[:, None, :] - a
    ap = points_px[None, :, :] - a
    length2 = ab[..., 0] * ab[..., 0] + ab[..., 1] * ab[..., 1]
    t = (ap[..., 0] * ab[..., 0] + ap[..., 1] * ab[..., 1]) / np.where(length2 > 0, length2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    dx = ap[..., 0] - t * ab[..., 0]
    dy = ap[..., 1] - t * ab[..., 1]
    return float(np.sqrt((dx * dx + dy * dy).min(axis=0).max()))


def resample_ring(ring_px: FloatArray, spacing_px: float) -> FloatArray:
    """Points every ``spacing_px`` (adjusted to divide the length evenly) along a closed ring."""
    x = np.append(ring_px[:, 0], ring_px[0, 0])
    y = np.append(ring_px[:, 1], ring_px[0, 1])
    dx = x[1:] - x[:-1]
    dy = y[1:] - y[:-1]
    cum = np.empty(len(x))
    cum[0] = 0.0
    np.cumsum(np.sqrt(dx * dx + dy * dy), out=cum[1:])
    total = float(cum[-1])
    n = max(3, round(total / spacing_px))
    if total == 0.0:
        return ring_px[:1].copy()
    s = np.arange(n, dtype=np.float64) * (total / n)
    out = np.empty((n, 2))
    out[:, 0] = np.interp(s, cum, x)
    out[:, 1] = np.interp(s, cum, y)
    return out


def offset_ring(ring_px: FloatArray, offset_px: float) -> FloatArray:
    """Move every edge of a ring by ``offset_px`` along its normal ``(dy, −dx)``.

    For the orientations :class:`~uavtool.vision.shapes.Shape` uses (outer ring positive,
    holes negative) this moves every edge away from the filled region.
    """
    if offset_px == 0.0 or len(ring_px) < 3:
        return ring_px
    pts = ring_px.tolist()
    normals: list[tuple[float, float]] = []
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True):
        dx, dy = x1 - x0, y1 - y0
        length = math.sqrt(dx * dx + dy * dy)
        if length == 0.0:
            length = 1.0
        normals.append((dy / length, -dx / length))
    min_denom = 2.0 / (_MAX_MITRE * _MAX_MITRE)
    out: list[tuple[float, float]] = []
    for (x, y), (nx, ny), (px, py) in zip(pts, normals, normals[-1:] + normals[:-1], strict=True):
        # Intersection of the two moved edge lines: offset · (n1 + n2) / (1 + n1·n2).
        denom = 1.0 + (nx * px + ny * py)
        scale = offset_px / (denom if denom >= min_denom else min_denom)
        out.append((x + (nx + px) * scale, y + (ny + py) * scale))
    return np.array(out, dtype=np.float64)
