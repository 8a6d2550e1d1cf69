"""Ramer–Douglas–Peucker simplification of open polylines and closed rings.

The output is a subset of the input points, in order, and every input point lies within
``epsilon_px`` of the simplified line (distance to the segment, not to its infinite line).

The recursion is run breadth first: every segment still to split, of every ring, is
handled by one set of array operations per level, so a frame's outlines cost a handful of
numpy calls per level instead of a few per segment. Each point's distance is computed with
the same IEEE operations in the same order as a plain per-segment loop, and the split point
is the first farthest one, so the result is that of the textbook recursion and the same on
every machine.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IndexArray = npt.NDArray[np.intp]


def rdp_indices(points_px: FloatArray, epsilon_px: float) -> IndexArray:
    """Indices of the points an open polyline ``(n, 2)`` keeps; first and last always kept."""
    pts = np.asarray(points_px, dtype=np.float64)
    n = len(pts)
    if n <= 2:
        return np.arange(n, dtype=np.intp)
    keep = _rdp_keep(
        pts[:, 0].copy(), pts[:, 1].copy(), np.array([0]), np.array([n - 1]), epsilon_px
    )
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
    return rdp_rings_indices([np.asarray(ring_px, dtype=np.float64)], epsilon_px)[0]


def rdp_rings_indices(rings_px: list[FloatArray], epsilon_px: float) -> list[IndexArray]:
    """:func:`rdp_ring_indices` of several rings ``(n_i, 2)`` at once (same results)."""
    out: list[IndexArray] = [np.arange(len(r), dtype=np.intp) for r in rings_px]
    todo = [k for k, r in enumerate(rings_px) if len(r) > 3]
    if not todo:
        return out
    cuts = _cut_points([rings_px[k] for k in todo])
    # Each ring doubled, so the chain from the second cut point back round to the first is
    # a plain slice; all rings side by side in one array.
    ext = np.concatenate([np.concatenate([rings_px[k], rings_px[k]]) for k in todo])
    xs, ys = ext[:, 0].copy(), ext[:, 1].copy()
    base = 0
    firsts: list[int] = []
    lasts: list[int] = []
    chains: dict[int, tuple[int, int, int]] = {}  # ring -> (offset in ext, a, b)
    for k, (a, b) in zip(todo, cuts, strict=True):
        n = len(rings_px[k])
        if a == b:
            out[k] = np.array([a], dtype=np.intp)
        else:
            i, j = min(a, b), max(a, b)
            firsts += [base + i, base + j]
            lasts += [base + j, base + i + n]
            chains[k] = (base, a, b)
        base += 2 * n
    if not chains:
        return out
    keep = _rdp_keep(xs, ys, np.array(firsts), np.array(lasts), epsilon_px)
    kept: dict[int, list[int]] = {}
    for k, (off, a, b) in chains.items():
        n = len(rings_px[k])
        i = min(a, b)
        kept[k] = [(i + q) % n for q in np.flatnonzero(keep[off + i : off + i + n]).tolist()]
    # The cut points are kept unconditionally; drop either one that RDP would not need
    # (on a rasterised outline the farthest point is often next to the corner, not on it).
    # Both checks go in one batch when the second cannot depend on the first (the two
    # anchors are not neighbours, and dropping one still leaves more than three points).
    eps2 = epsilon_px * epsilon_px
    pending = {k: [a, b] for k, (_, a, b) in chains.items()}
    while pending:
        check: list[tuple[int, int]] = []  # (ring, anchor)
        f: list[int] = []
        last: list[int] = []
        for k, anchors in pending.items():
            ring_kept = kept[k]
            m = len(ring_kept)
            take = anchors[:1] if m > 3 else []
            if len(anchors) == 2 and m >= 5:
                gap = ring_kept.index(anchors[0]) - ring_kept.index(anchors[1])
                if gap % m not in (1, m - 1):
                    take = anchors
            for anchor in take:
                pos = ring_kept.index(anchor)
                prev, nxt = ring_kept[pos - 1], ring_kept[(pos + 1) % m]
                off = chains[k][0]
                check.append((k, anchor))
                f.append(off + prev)
                last.append(off + (nxt if nxt > prev else nxt + len(rings_px[k])))
            pending[k] = anchors[len(take) :] if take else []
        pending = {k: anchors for k, anchors in pending.items() if anchors}
        if not check:
            break
        worst, _ = _farthest(xs, ys, np.array(f), np.array(last))
        for (k, anchor), d2 in zip(check, worst.tolist(), strict=True):
            if d2 <= eps2:
                kept[k].remove(anchor)
    for k, ring_kept in kept.items():
        out[k] = np.array(ring_kept, dtype=np.intp)
    return out


def _cut_points(rings: list[FloatArray]) -> list[tuple[int, int]]:
    """For each ring: the point farthest from its vertex mean, and the point farthest from
    that one (first of equals, as ``argmax``)."""
    ns = np.array([len(r) for r in rings])
    starts = np.cumsum(ns) - ns
    xs = np.concatenate([r[:, 0] for r in rings])
    ys = np.concatenate([r[:, 1] for r in rings])
    xl, yl = xs.tolist(), ys.tolist()
    bounds = list(zip(starts.tolist(), (starts + ns).tolist(), strict=True))
    cx = np.repeat(np.array([math.fsum(xl[s:e]) / (e - s) for s, e in bounds]), ns)
    cy = np.repeat(np.array([math.fsum(yl[s:e]) / (e - s) for s, e in bounds]), ns)
    a = _first_max(xs - cx, ys - cy, starts, ns)
    b = _first_max(xs - np.repeat(xs[a], ns), ys - np.repeat(ys[a], ns), starts, ns)
    return [(int(i) - s, int(j) - s) for i, j, s in zip(a, b, starts.tolist(), strict=True)]


def _first_max(dx: FloatArray, dy: FloatArray, starts: IndexArray, ns: IndexArray) -> IndexArray:
    """Per group of ``ns`` points from ``starts``: index of the first largest ``dx² + dy²``."""
    d2 = dx * dx + dy * dy
    worst = np.repeat(np.maximum.reduceat(d2, starts), ns)
    at = np.where(d2 == worst, np.arange(len(d2)), len(d2))
    return np.minimum.reduceat(at, starts)


def _rdp_keep(
    xs: FloatArray, ys: FloatArray, firsts: IndexArray, lasts: IndexArray, epsilon_px: float
) -> npt.NDArray[np.bool_]:
    """Which of the points ``(xs, ys)`` RDP keeps on the segments ``firsts[s]…lasts[s]``."""
    eps2 = epsilon_px * epsilon_px
    keep = np.zeros(len(xs), dtype=bool)
    keep[firsts] = True
    keep[lasts] = True
    f, last = firsts, lasts
    while True:
        long = last - f >= 2
        f, last = f[long], last[long]
        if len(f) == 0:
            return keep
        worst, at = _farthest(xs, ys, f, last)
        split = worst > eps2
        k = at[split]
        keep[k] = True
        f, last = np.concatenate([f[split], k]), np.concatenate([k, last[split]])


def _farthest(
    xs: FloatArray, ys: FloatArray, f: IndexArray, last: IndexArray
) -> tuple[FloatArray, IndexArray]:
    """For each segment ``f[s]``–``last[s]`` of the points ``(xs, ys)`` (``last[s] ≥ f[s] +
    2``): the largest squared distance to the segment of the points strictly between, and
    the index of the first point at that distance."""
    count = last - f - 1
    seg = np.repeat(np.arange(len(f)), count)
    starts = np.cumsum(count) - count
    idx = np.arange(len(seg)) + (f + 1 - starts)[seg]
    ax, ay = xs[f], ys[f]
    abx, aby = xs[last] - ax, ys[last] - ay
    len2 = abx * abx + aby * aby
    apx, apy = xs[idx] - ax[seg], ys[idx] - ay[seg]
    abx, aby, len2 = abx[seg], aby[seg], len2[seg]
    degenerate = len2 == 0.0
    if degenerate.any():
        len2[degenerate] = 1.0
    t = (apx * abx + apy * aby) / len2
    np.maximum(t, 0.0, out=t)
    np.minimum(t, 1.0, out=t)
    dx = apx - t * abx
    dy = apy - t * aby
    d2 = dx * dx + dy * dy
    if degenerate.any():
        d2[degenerate] = (apx * apx + apy * apy)[degenerate]
    worst = np.maximum.reduceat(d2, starts)
    # The first point at the maximum (what a per-segment argmax would pick).
    at_max = np.where(d2 == worst[seg], idx, len(xs))
    return worst, np.minimum.reduceat(at_max, starts)
