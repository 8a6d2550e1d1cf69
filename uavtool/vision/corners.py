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
    spans: list[tuple[int, int]] = []  # (first, last) dense indices of each long edge
    for e in range(m):
        first, last = kept[e], kept[(e + 1) % m]
        chord = dense_px[last] - dense_px[first]
        if (last - first) % n >= 2 and math.hypot(float(chord[0]), float(chord[1])) >= min_edge_px:
            spans.append((first, last))
    lines = [_fit_span(dense_px, first, last) for first, last in spans]
    # Merge neighbouring edges that are one straight line (a vertex RDP kept for a rounded
    # or noisy stretch), refitting the merged span, until none is left.
    k = 0
    while len(lines) > 3 and k < len(lines):
        j = (k + 1) % len(lines)
        (_, _, dx1, dy1), (_, _, dx2, dy2) = lines[k], lines[j]
        if abs(dx1 * dy2 - dy1 * dx2) < _MIN_SINE and dx1 * dx2 + dy1 * dy2 > 0.0:
            spans[k] = (spans[k][0], spans[j][1])
            lines[k] = _fit_span(dense_px, *spans[k])
            del spans[j], lines[j]
            k = max(k - 1, 0) if j > k else k - 1
            continue
        k += 1
    if len(lines) < 3:
        return dense_px[kept].copy()
    corners: list[tuple[float, float]] = []
    for k in range(len(lines)):
        cx1, cy1, dx1, dy1 = lines[k - 1]
        cx2, cy2, dx2, dy2 = lines[k]
        end_prev, start_next = spans[k - 1][1], spans[k][0]
        cross = dx1 * dy2 - dy1 * dx2
        if abs(cross) < _MIN_SINE:
            # Parallel edges joined by a stub (a small step): keep the stub's ends.
            corners.append(tuple(dense_px[end_prev].tolist()))
            if start_next != end_prev:
                corners.append(tuple(dense_px[start_next].tolist()))
            continue
        t = ((cx2 - cx1) * dy2 - (cy2 - cy1) * dx2) / cross
        px, py = cx1 + t * dx1, cy1 + t * dy1
        vx, vy = dense_px[end_prev].tolist()
        if math.hypot(px - vx, py - vy) > max_shift_px:
            corners.append((vx, vy))
        else:
            corners.append((px, py))
    if len(corners) < 3:
        return dense_px[kept].copy()
    return np.array(corners, dtype=np.float64)


def _fit_span(dense_px: FloatArray, first: int, last: int) -> tuple[float, float, float, float]:
    """Line through the dense points ``first`` … ``last`` (cyclic), without the end points
    when there are enough (an RDP vertex next to a corner may lie on the next edge)."""
    n = len(dense_px)
    count = (last - first) % n + 1
    trim = 1 if count >= 6 else 0
    idx = [(first + t) % n for t in range(trim, count - trim)]
    cx, cy, dx, dy = _fit_line(dense_px[idx])
    # Point the (unoriented) fitted axis the way the outline runs, so that antiparallel
    # edges (the two sides of a narrow slot) are never taken for one straight line.
    chord = dense_px[last] - dense_px[first]
    if dx * float(chord[0]) + dy * float(chord[1]) < 0.0:
        dx, dy = -dx, -dy
    return cx, cy, dx, dy


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
