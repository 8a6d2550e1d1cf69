"""Ramer–Douglas–Peucker simplification of open polylines and closed rings.

The output is a subset of the input points, in order, and every input point lies within
``epsilon_px`` of the simplified line (distance to the segment, not to its infinite line).
Only IEEE arithmetic, so results are the same on every machine.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IndexArray = npt.NDArray[np.intp]


def rdp_indices(points_px: FloatArray, epsilon_px: float) -> IndexArray:
    """Indices of the points an open polyline ``(n, 2)`` keeps; first and last always kept."""
    n = len(points_px)
    if n <= 2:
        return np.arange(n, dtype=np.intp)
    eps2 = epsilon_px * epsilon_px
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[n - 1] = True
    stack = [(0, n - 1)]
    while stack:
        first, last = stack.pop()
        if last - first < 2:
            continue
        d2 = _segment_dist2(points_px[first + 1 : last], points_px[first], points_px[last])
        k = int(np.argmax(d2))
        if d2[k] > eps2:
            split = first + 1 + k
            keep[split] = True
            stack.append((split, last))
            stack.append((first, split))
    return np.flatnonzero(keep)


def rdp(points_px: FloatArray, epsilon_px: float) -> FloatArray:
    """Simplified open polyline ``(m, 2)``, a subset of ``points_px`` ``(n, 2)``."""
    pts = np.asarray(points_px, dtype=np.float64)
    return pts[rdp_indices(pts, epsilon_px)]


def rdp_ring(ring_px: FloatArray, epsilon_px: float) -> FloatArray:
    """Simplified closed ring ``(m, 2)`` (no repeated closing point), a subset of the input."""
    pts = np.asarray(ring_px, dtype=np.float64)
    out: FloatArray = pts[rdp_ring_indices(pts, epsilon_px)]
    return out


def rdp_ring_indices(ring_px: FloatArray, epsilon_px: float) -> IndexArray:
    """Indices (in cyclic order) of the points a closed ring ``(n, 2)`` keeps.

    The ring is cut at two extreme points — the one farthest from the vertex mean and the
    one farthest from that — which are corners of any polygon, so no vertex is kept only
    because the cut happened there.
    """
    pts = np.asarray(ring_px, dtype=np.float64)
    n = len(pts)
    if n <= 3:
        return np.arange(n, dtype=np.intp)
    centre = np.array([math.fsum(pts[:, 0].tolist()) / n, math.fsum(pts[:, 1].tolist()) / n])
    d0 = pts - centre
    a = int(np.argmax(d0[:, 0] * d0[:, 0] + d0[:, 1] * d0[:, 1]))
    da = pts - pts[a]
    b = int(np.argmax(da[:, 0] * da[:, 0] + da[:, 1] * da[:, 1]))
    if a == b:
        return np.array([a], dtype=np.intp)
    i, j = min(a, b), max(a, b)
    chain1 = pts[i : j + 1]
    chain2 = np.concatenate([pts[j:], pts[: i + 1]])
    keep1 = rdp_indices(chain1, epsilon_px) + i
    keep2 = (rdp_indices(chain2, epsilon_px) + j) % n
    kept = np.concatenate([keep1, keep2[1:-1]]).tolist()
    # The cut points are kept unconditionally; drop either one that RDP would not need
    # (on a rasterised outline the farthest point is often next to the corner, not on it).
    for anchor in (a, b):
        k = kept.index(anchor)
        m = len(kept)
        if m <= 3:
            break
        prev, nxt = kept[k - 1], kept[(k + 1) % m]
        span = _cyclic_slice(pts, prev, nxt)
        if float(np.max(_segment_dist2(span, pts[prev], pts[nxt]))) <= epsilon_px * epsilon_px:
            del kept[k]
    return np.array(kept, dtype=np.intp)


def _cyclic_slice(pts: FloatArray, first: int, last: int) -> FloatArray:
    """Points ``first`` … ``last`` inclusive, wrapping around the end of the ring."""
    if last >= first:
        return pts[first : last + 1]
    return np.concatenate([pts[first:], pts[: last + 1]])


def _segment_dist2(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Squared distance of each point ``(n, 2)`` to the segment ``a``–``b``."""
    ab = b - a
    ap = points - a
    len2 = float(ab[0] * ab[0] + ab[1] * ab[1])
    if len2 == 0.0:
        return ap[:, 0] * ap[:, 0] + ap[:, 1] * ap[:, 1]
    t = np.clip((ap[:, 0] * ab[0] + ap[:, 1] * ab[1]) / len2, 0.0, 1.0)
    dx = ap[:, 0] - t * ab[0]
    dy = ap[:, 1] - t * ab[1]
    out: FloatArray = dx * dx + dy * dy
    return out
