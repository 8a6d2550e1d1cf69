"""Corner refinement: put each corner of an RDP outline where its two edges actually meet.

Evenly spaced points rarely fall exactly on a corner, so RDP keeps a point next to it — or
two, one on each side (a split corner). Here every edge of the simplified ring that spans
enough of the dense points gets a least-squares line through them; a corner becomes the
intersection of two consecutive such lines, and edges too short to fit (the stub between
the two halves of a split corner) disappear. Scalars use ``math`` and ``math.fsum``, so the
result is the same on every machine.
"""

from __future__ import annotations

import math

import numpy as np

from uavtool.vision.shapes import FloatArray

# Consecutive lines closer to parallel than this (sine of the angle) do not make a corner.
_MIN_SINE = 0.05


def refine_corners(
    dense_px: FloatArray, kept: list[int], *, min_edge_px: float, max_shift_px: float
) -> FloatArray:
    """Corners ``(m, 2)`` of a ring whose RDP vertices are ``dense_px[kept]``.

    ``dense_px`` : (n, 2) — the evenly spaced border points; ``kept`` — RDP's vertex indices
    in cyclic order. Edges shorter than ``min_edge_px`` are corner stubs and dropped. A
    refined corner further than ``max_shift_px`` from the RDP vertex it replaces (nearly
    parallel edges) falls back to that vertex.
    """
    n, m = len(dense_px), len(kept)
    if m < 3:
        return dense_px[kept].copy()
    lines: list[tuple[float, float, float, float, int]] = []  # cx, cy, dx, dy, edge index
    for e in range(m):
        first, last = kept[e], kept[(e + 1) % m]
        count = (last - first) % n + 1
        chord = dense_px[last] - dense_px[first]
        if count < 3 or math.hypot(float(chord[0]), float(chord[1])) < min_edge_px:
            continue
        # Interior points only when there are enough: an RDP vertex next to a corner may
        # already lie on the following edge.
        trim = 1 if count >= 6 else 0
        idx = [(first + t) % n for t in range(trim, count - trim)]
        lines.append((*_fit_line(dense_px[idx]), e))
    if len(lines) < 3:
        return dense_px[kept].copy()
    corners: list[tuple[float, float]] = []
    for k in range(len(lines)):
        cx1, cy1, dx1, dy1, e1 = lines[k - 1]
        cx2, cy2, dx2, dy2, _ = lines[k]
        # The RDP vertex that ends edge e1 (start of the following edge).
        vx, vy = dense_px[kept[(e1 + 1) % m]].tolist()
        cross = dx1 * dy2 - dy1 * dx2
        if abs(cross) < _MIN_SINE:
            if e1 == (lines[k][4] - 1) % m:
                corners.append((vx, vy))  # a straight joint: keep the vertex
            continue
        t = ((cx2 - cx1) * dy2 - (cy2 - cy1) * dx2) / cross
        px, py = cx1 + t * dx1, cy1 + t * dy1
        if math.hypot(px - vx, py - vy) > max_shift_px:
            corners.append((vx, vy))
        else:
            corners.append((px, py))
    if len(corners) < 3:
        return dense_px[kept].copy()
    return np.array(corners, dtype=np.float64)


def _fit_line(pts: FloatArray) -> tuple[float, float, float, float]:
    """Total-least-squares line through points ``(k, 2)``: centre and unit direction."""
    xs = pts[:, 0].tolist()
    ys = pts[:, 1].tolist()
    k = len(xs)
    cx = math.fsum(xs) / k
    cy = math.fsum(ys) / k
    dxs = [x - cx for x in xs]
    dys = [y - cy for y in ys]
    sxx = math.fsum(d * d for d in dxs)
    syy = math.fsum(d * d for d in dys)
    sxy = math.fsum(a * b for a, b in zip(dxs, dys, strict=True))
    angle = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    return cx, cy, math.cos(angle), math.sin(angle)
