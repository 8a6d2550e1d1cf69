"""Ramer–Douglas–Peucker simplification of open polylines and closed rings.

The output is a subset of the input points, in order, and every input point lies within
``epsilon_px`` of the simplified line (distance to the segment, not to its infinite line).

GEOS runs the recursion (``shapely.simplify`` without topology preservation is the textbook
algorithm: distance to the segment, split at the first farthest point); every chain of
every ring of a frame goes to it in one call. A point's index rides along as its z
coordinate, which GEOS copies but does not measure, so the result is a set of indices.
What is decided here — where a ring is cut, which cut point to drop — uses exact float
arithmetic in a fixed order, so the result is the same on every machine with the same GEOS.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import shapely

FloatArray = npt.NDArray[np.float64]
IndexArray = npt.NDArray[np.intp]


def rdp_indices(points_px: FloatArray, epsilon_px: float) -> IndexArray:
    """Indices of the points an open polyline ``(n, 2)`` keeps; first and last always kept."""
    pts = np.asarray(points_px, dtype=np.float64)
    n = len(pts)
    if n <= 2:
        return np.arange(n, dtype=np.intp)
    return np.sort(
        _simplify(pts[:, 0].copy(), pts[:, 1].copy(), np.arange(n), np.array([n]), epsilon_px)
    )


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
    one farthest from that — which are corners of any polygon, and each half simplified as
    an open line. A cut point is then dropped if RDP would not need it (every point between
    its two neighbours within epsilon of the segment joining them), so no vertex is kept
    only because the cut happened there.
    """
    return rdp_rings_indices([np.asarray(ring_px, dtype=np.float64)], epsilon_px)[0]


def rdp_rings_indices(rings_px: list[FloatArray], epsilon_px: float) -> list[IndexArray]:
    """:func:`rdp_ring_indices` of several rings ``(n_i, 2)`` at once (same results)."""
    out: list[IndexArray] = [np.arange(len(r), dtype=np.intp) for r in rings_px]
    todo = [k for k, r in enumerate(rings_px) if len(r) > 3]
    if not todo:
        return out
    pts = np.concatenate([rings_px[k] for k in todo])
    xs, ys = pts[:, 0].copy(), pts[:, 1].copy()
    ns = np.array([len(rings_px[k]) for k in todo])
    bases = np.cumsum(ns) - ns
    # Cut each ring at the point farthest from its vertex mean and at the point farthest
    # from that one: both are corners of any polygon.
    xl, yl = xs.tolist(), ys.tolist()
    bounds = list(zip(bases.tolist(), (bases + ns).tolist(), strict=True))
    cx = np.repeat(np.array([math.fsum(xl[s:e]) / (e - s) for s, e in bounds]), ns)
    cy = np.repeat(np.array([math.fsum(yl[s:e]) / (e - s) for s, e in bounds]), ns)
    a = _first_max(xs - cx, ys - cy, bases, ns)
    b = _first_max(xs - np.repeat(xs[a], ns), ys - np.repeat(ys[a], ns), bases, ns)
    a, b = a - bases, b - bases
    cut = a != b  # else every point of the ring is the same point
    for k, at in zip(np.asarray(todo)[~cut].tolist(), a[~cut].tolist(), strict=True):
        out[k] = np.array([at], dtype=np.intp)
    if not cut.any():
        return out
    # Two chains per ring, i…j and j…i+n (cyclic) for the cut points i < j.
    a, b, n = a[cut], b[cut], ns[cut]
    i, j = np.minimum(a, b), np.maximum(a, b)
    count = np.stack([j - i + 1, n - j + i + 1], axis=1).ravel()
    first = np.stack([i, j], axis=1).ravel()
    idx = _cyclic_runs(np.repeat(bases[cut], 2), first, count, np.repeat(n, 2))
    keep = np.zeros(len(xs), dtype=bool)
    keep[_simplify(xs, ys, idx, count, epsilon_px)] = True
    rings = [  # (ring, its first index in xs, its length, its two cut points)
        (k, s, m, (p, q))
        for k, s, m, p, q in zip(
            np.asarray(todo)[cut].tolist(),
            bases[cut].tolist(),
            n.tolist(),
            a.tolist(),
            b.tolist(),
            strict=True,
        )
    ]
    # Each ring's kept points in cyclic order from its first cut point.
    kept: dict[int, list[int]] = {}
    for k, s, m, (p, q) in rings:
        at = np.flatnonzero(keep[s : s + m]).tolist()
        first_cut = at.index(min(p, q))
        kept[k] = at[first_cut:] + at[:first_cut]
    # Drop a cut point RDP would not need (on a rasterised outline the farthest point is
    # often next to the corner, not on it). Both checks go in one batch when the second
    # cannot depend on the first: the two are not neighbours, and dropping one still
    # leaves more than three points.
    pending = {k: list(ab) for k, _, _, ab in rings}
    where = {k: (s, m) for k, s, m, _ in rings}
    while pending:
        check: list[tuple[int, int]] = []  # (ring, cut point)
        prevs: list[int] = []
        nexts: list[int] = []
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
                check.append((k, anchor))
                prevs.append(ring_kept[pos - 1])
                nexts.append(ring_kept[(pos + 1) % m])
            pending[k] = anchors[len(take) :] if take else []
        pending = {k: anchors for k, anchors in pending.items() if anchors}
        if not check:
            break
        s_arr = np.array([where[k][0] for k, _ in check])
        m_arr = np.array([where[k][1] for k, _ in check])
        prev, nxt = np.array(prevs), np.array(nexts)
        inner = (nxt - prev) % m_arr - 1  # the points between the neighbours, cut point included
        between = _cyclic_runs(s_arr, prev + 1, inner, m_arr)
        ok = _within(xs, ys, between, inner, s_arr + prev, s_arr + nxt, epsilon_px)
        for (k, anchor), drop in zip(check, ok, strict=True):
            if drop:
                kept[k].remove(anchor)
    for k, ring_kept in kept.items():
        out[k] = np.array(ring_kept, dtype=np.intp)
    return out


def _cyclic_runs(
    bases: IndexArray, firsts: IndexArray, counts: IndexArray, ns: IndexArray
) -> IndexArray:
    """Indices of runs of points: ``counts[c]`` points from ``firsts[c]`` on, cyclic in a
    ring of ``ns[c]`` points that starts at ``bases[c]``; all runs one after the other."""
    offsets = np.cumsum(counts) - counts
    step = np.arange(int(offsets[-1] + counts[-1])) - np.repeat(offsets, counts)
    return np.repeat(bases, counts) + (np.repeat(firsts, counts) + step) % np.repeat(ns, counts)


def _simplify(
    xs: FloatArray, ys: FloatArray, idx: IndexArray, counts: IndexArray, epsilon_px: float
) -> IndexArray:
    """RDP of the open chains of points ``idx`` (``counts[c]`` for chain ``c``, one after the
    other) of ``(xs, ys)``: the indices into ``xs`` of the points kept."""
    coords = np.stack([xs[idx], ys[idx], idx.astype(np.float64)], axis=1)
    lines = shapely.linestrings(coords, indices=np.repeat(np.arange(len(counts)), counts))
    # Coordinates a subnormal distance apart make GEOS's squared segment length underflow
    # to 0 and divide by it; pixel coordinates never come that close without being equal.
    with np.errstate(divide="ignore", invalid="ignore"):
        simple = shapely.simplify(lines, epsilon_px, preserve_topology=False)
    kept: IndexArray = shapely.get_coordinates(simple, include_z=True)[:, 2].astype(np.intp)
    return kept


def _within(
    xs: FloatArray,
    ys: FloatArray,
    idx: IndexArray,
    counts: IndexArray,
    a: IndexArray,
    b: IndexArray,
    epsilon_px: float,
) -> list[bool]:
    """For each group of ``counts[c]`` points ``idx`` (one after the other; ``counts[c] ≥
    1``): do all lie within ``epsilon_px`` of the segment from point ``a[c]`` to ``b[c]``?"""
    seg = np.repeat(np.arange(len(counts)), counts)
    ax, ay = xs[a], ys[a]
    abx, aby = xs[b] - ax, ys[b] - ay
    len2 = abx * abx + aby * aby
    apx, apy = xs[idx] - ax[seg], ys[idx] - ay[seg]
    abx, aby, len2 = abx[seg], aby[seg], len2[seg]
    t = np.divide(apx * abx + apy * aby, len2, out=np.zeros(len(idx)), where=len2 > 0.0)
    np.clip(t, 0.0, 1.0, out=t)
    dx, dy = apx - t * abx, apy - t * aby
    worst = np.maximum.reduceat(dx * dx + dy * dy, np.cumsum(counts) - counts)
    ok: list[bool] = (worst <= epsilon_px * epsilon_px).tolist()
    return ok


def _first_max(dx: FloatArray, dy: FloatArray, starts: IndexArray, ns: IndexArray) -> IndexArray:
    """Per group of ``ns`` points from ``starts``: index of the first largest ``dx² + dy²``."""
    d2 = dx * dx + dy * dy
    worst = np.repeat(np.maximum.reduceat(d2, starts), ns)
    at = np.where(d2 == worst, np.arange(len(d2)), len(d2))
    return np.minimum.reduceat(at, starts)
