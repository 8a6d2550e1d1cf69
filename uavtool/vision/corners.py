"""Corner refinement: put each corner of an RDP outline where its two edges actually meet.

Evenly spaced points rarely fall exactly on a corner, so RDP keeps a point next to it — or
two, one on each side (a split corner). Here every edge of the simplified ring that spans
enough of the dense points gets a least-squares line through them; a corner becomes the
intersection of two consecutive such lines, and edges too short to fit (the stub between
the two halves of a split corner) disappear, and neighbouring edges that are one straight
line are joined. Sums use ``math.fsum`` and scalars ``math`` (numpy only for element-wise
products and exact maxima), so the result is the same on every machine.
"""

from __future__ import annotations

import math

import numpy as np

from uavtool.vision.shapes import FloatArray

# Consecutive lines closer to parallel than this (sine of the angle) do not make a corner.
_MIN_SINE = 0.05
# Lines further apart than this (sine, ~15°) always make a corner.
_MAX_MERGE_SINE = 0.25

Line = tuple[float, float, float, float]  # centre x, y and unit direction x, y
Span = tuple[int, int]  # first and last dense index of an edge (cyclic)


def refine_corners(
    dense_px: FloatArray,
    kept: list[int],
    *,
    min_edge_px: float,
    max_shift_px: float,
    straight_tolerance_px: float = 0.0,
    join_tolerance_px: float = 0.0,
) -> FloatArray:
    """Corners ``(m, 2)`` of a ring whose RDP vertices are ``dense_px[kept]``.

    ``dense_px`` : (n, 2) — the evenly spaced border points; ``kept`` — RDP's vertex indices
    in cyclic order. Edges shorter than ``min_edge_px`` are corner stubs and dropped, unless
    consecutive short edges are together one straight edge of at least ``min_edge_px``: all
    their border points within ``join_tolerance_px`` of the line from the first to the last
    (RDP splits a short edge whose staircase strays a little more than its epsilon). A
    refined corner further than ``max_shift_px`` from the RDP vertex it replaces (nearly
    parallel edges) falls back to that vertex.
    """
    return refine_rings(
        [dense_px],
        [kept],
        min_edge_px=min_edge_px,
        max_shift_px=max_shift_px,
        straight_tolerance_px=straight_tolerance_px,
        join_tolerance_px=join_tolerance_px,
    )[0]


def refine_rings(
    dense_px: list[FloatArray],
    kept: list[list[int]],
    *,
    min_edge_px: float,
    max_shift_px: float,
    straight_tolerance_px: float = 0.0,
    join_tolerance_px: float = 0.0,
) -> list[FloatArray]:
    """:func:`refine_corners` of several rings at once (the line fits share array calls)."""
    # The RDP vertices as Python floats, by dense index: every span starts and ends at one.
    vertices = [
        dict(zip(k, d[k].tolist(), strict=True)) for d, k in zip(dense_px, kept, strict=True)
    ]
    spans = [
        _long_edges(d, k, v, min_edge_px, join_tolerance_px)
        for d, k, v in zip(dense_px, kept, vertices, strict=True)
    ]
    lines = _fit_spans(dense_px, spans, vertices)
    out: list[FloatArray] = []
    for r, dense in enumerate(dense_px):
        corners = None
        if len(kept[r]) >= 3:
            corners = _corners(
                dense, vertices[r], spans[r], lines[r], max_shift_px, straight_tolerance_px
            )
        out.append(dense[kept[r]].copy() if corners is None else corners)
    return out


def _long_edges(
    dense: FloatArray,
    kept: list[int],
    vertices: dict[int, list[float]],
    min_edge_px: float,
    join_px: float,
) -> list[Span]:
    """The edges of the RDP ring long enough to fit a line to; with ``join_px``, also each
    run of short edges that is one straight edge long enough (see :func:`refine_corners`)."""
    n, m = len(dense), len(kept)
    if m < 3:
        return []

    def long_enough(first: int, last: int) -> bool:
        (x0, y0), (x1, y1) = vertices[first], vertices[last]
        return (last - first) % n >= 2 and math.hypot(x1 - x0, y1 - y0) >= min_edge_px

    edges = [(kept[e], kept[(e + 1) % m]) for e in range(m)]
    long = [long_enough(first, last) for first, last in edges]
    if join_px <= 0.0 or all(long) or not any(long):
        return [edge for edge, ok in zip(edges, long, strict=True) if ok]
    # From a long edge's start, so that no run of short edges wraps past the scan's end.
    start = long.index(True)
    order = [kept[(start + i) % m] for i in range(m + 1)]
    flags = long[start:] + long[:start]
    spans: list[Span] = []
    e = 0
    while e < m:
        if flags[e]:
            spans.append((order[e], order[e + 1]))
            e += 1
            continue
        best, end = 0, e
        while end < m and not flags[end]:
            end += 1
            if not _straight(dense, vertices, order[e], order[end], join_px):
                break
            if long_enough(order[e], order[end]):
                best = end
        joined = (order[e], order[best]) if best else None
        # the long edges either side (the scan starts at a long edge: e > 0 here, and a run
        # that reaches the scan's end is followed by the first edge)
        after = best % m
        if joined is not None and not (
            (flags[e - 1] and _along(vertices, (order[e - 1], order[e]), joined, join_px))
            or (
                flags[after] and _along(vertices, (order[after], order[after + 1]), joined, join_px)
            )
        ):
            spans.append(joined)
            e = best
        else:
            e += 1
    return spans


def _along(vertices: dict[int, list[float]], edge: Span, joined: Span, join_px: float) -> bool:
    """Whether a joined run of short edges runs the way of its long neighbour ``edge``, as
    far as its direction is known (each end to ``join_px`` across, over its length): then it
    is the ragged end of that edge round a corner, not an edge of its own."""
    (ax, ay), (bx, by) = vertices[edge[0]], vertices[edge[1]]
    (cx, cy), (dx, dy) = vertices[joined[0]], vertices[joined[1]]
    ux, uy, vx, vy = bx - ax, by - ay, dx - cx, dy - cy
    long, short = math.hypot(ux, uy), math.hypot(vx, vy)
    if long == 0.0 or short == 0.0:
        return True
    sine = abs(ux * vy - uy * vx) / (long * short)
    return ux * vx + uy * vy > 0.0 and sine < min(1.0, 2.0 * join_px / short)


def _straight(
    dense: FloatArray, vertices: dict[int, list[float]], first: int, last: int, tol_px: float
) -> bool:
    """Whether every border point from ``first`` to ``last`` lies within ``tol_px`` of the
    line through those two vertices."""
    pts = _ring_slice(dense, first, (last - first) % len(dense) + 1)
    (x0, y0), (x1, y1) = vertices[first], vertices[last]
    dx, dy = x1 - x0, y1 - y0
    length = math.hypot(dx, dy)
    if length == 0.0:
        return False
    off = np.abs((pts[:, 0] - x0) * dy - (pts[:, 1] - y0) * dx) / length
    return float(off.max()) <= tol_px


def _corners(
    dense: FloatArray,
    vertices: dict[int, list[float]],
    spans: list[Span],
    lines: list[Line],
    max_shift_px: float,
    tol_px: float,
) -> FloatArray | None:
    """Intersections of consecutive fitted lines (None: too few lines for a polygon)."""
    # Merge neighbouring edges that are one straight line (a vertex RDP kept for a rounded
    # or noisy stretch), refitting the merged span, until none is left.
    k = 0
    while len(lines) > 3 and k < len(lines):
        j = (k + 1) % len(lines)
        merged = _one_line(dense, vertices, (spans[k][0], spans[j][1]), lines[k], lines[j], tol_px)
        if merged is not None:
            spans[k] = (spans[k][0], spans[j][1])
            lines[k] = merged
            del spans[j], lines[j]
            k = max(k - 1, 0) if j > k else k - 1
            continue
        k += 1
    if len(lines) < 3:
        return None
    corners: list[tuple[float, float]] = []
    for k in range(len(lines)):
        cx1, cy1, dx1, dy1 = lines[k - 1]
        cx2, cy2, dx2, dy2 = lines[k]
        end_prev, start_next = spans[k - 1][1], spans[k][0]
        vx, vy = vertices[end_prev]
        cross = dx1 * dy2 - dy1 * dx2
        if abs(cross) < _MIN_SINE:
            # Parallel edges joined by a stub (a small step): keep the stub's ends.
            corners.append((vx, vy))
            if start_next != end_prev:
                wx, wy = vertices[start_next]
                corners.append((wx, wy))
            continue
        t = ((cx2 - cx1) * dy2 - (cy2 - cy1) * dx2) / cross
        px, py = cx1 + t * dx1, cy1 + t * dy1
        if math.hypot(px - vx, py - vy) > max_shift_px:
            corners.append((vx, vy))
        else:
            corners.append((px, py))
    if len(corners) < 3:
        return None
    return np.array(corners, dtype=np.float64)


def _fit_spans(
    dense_px: list[FloatArray], spans: list[list[Span]], vertices: list[dict[int, list[float]]]
) -> list[list[Line]]:
    """A total-least-squares line through the dense points of each span, without the end
    points when there are enough (an RDP vertex next to a corner may lie on the next edge),
    its direction pointing the way the outline runs — so the two antiparallel sides of a
    narrow slot are never taken for one straight line."""
    starts: list[int] = []
    counts: list[int] = []
    base = 0
    for dense, ring_spans in zip(dense_px, spans, strict=True):
        n = len(dense)
        for first, last in ring_spans:
            count = (last - first) % n + 1
            trim = 1 if count >= 6 else 0
            starts.append(base + first + trim)
            counts.append(count - 2 * trim)
        base += 2 * n
    if not starts:
        return [[] for _ in spans]
    # Each ring doubled so a span running past the last point is a plain slice.
    xs = np.concatenate([d[:, 0] for d in dense_px for _ in (0, 1)])
    ys = np.concatenate([d[:, 1] for d in dense_px for _ in (0, 1)])
    count_arr = np.array(counts)
    offsets = np.cumsum(count_arr) - count_arr
    idx = np.repeat(np.array(starts) - offsets, count_arr)
    idx += np.arange(len(idx))
    gx, gy = xs[idx], ys[idx]
    gxl, gyl = gx.tolist(), gy.tolist()
    bounds = list(zip(offsets.tolist(), (offsets + count_arr).tolist(), strict=True))
    cxs = [math.fsum(gxl[a:b]) / (b - a) for a, b in bounds]
    cys = [math.fsum(gyl[a:b]) / (b - a) for a, b in bounds]
    gx -= np.repeat(np.array(cxs), count_arr)
    gy -= np.repeat(np.array(cys), count_arr)
    sxx_t, syy_t, sxy_t = (gx * gx).tolist(), (gy * gy).tolist(), (gx * gy).tolist()
    out: list[list[Line]] = []
    s = 0
    for ring_spans, ring_vertices in zip(spans, vertices, strict=True):
        ring_lines: list[Line] = []
        for first, last in ring_spans:
            a, b = bounds[s]
            sums = (math.fsum(sxx_t[a:b]), math.fsum(syy_t[a:b]), math.fsum(sxy_t[a:b]))
            ring_lines.append(
                _line(cxs[s], cys[s], sums, ring_vertices[first], ring_vertices[last])
            )
            s += 1
        out.append(ring_lines)
    return out


def _one_line(
    dense: FloatArray,
    vertices: dict[int, list[float]],
    span: Span,
    line1: Line,
    line2: Line,
    tol_px: float,
) -> Line | None:
    """The line of two neighbouring edges that are one straight edge, else None.

    They are when their directions are within ~3° — or, up to ~15° apart, when every point
    of the two lies within ``tol_px`` of one line fitted to both: a short edge's direction
    is only known to about a pixel over its length, so a stretch of a slanted edge that
    rasterised as one straight run can look a few degrees off.
    """
    _, _, dx1, dy1 = line1
    _, _, dx2, dy2 = line2
    sine = abs(dx1 * dy2 - dy1 * dx2)
    if dx1 * dx2 + dy1 * dy2 <= 0.0 or sine >= _MAX_MERGE_SINE:
        return None
    if sine < _MIN_SINE:
        return _fit_span(dense, span, vertices)
    if tol_px <= 0.0:
        return None
    line = _fit_span(dense, span, vertices)
    cx, cy, ux, uy = line
    pts = _span_points(dense, span)
    off = np.abs((pts[:, 0] - cx) * uy - (pts[:, 1] - cy) * ux)
    return line if float(off.max()) <= tol_px else None


def _span_points(dense: FloatArray, span: Span) -> FloatArray:
    """The dense points a line is fitted to: the span without its end points when long."""
    n = len(dense)
    first, last = span
    count = (last - first) % n + 1
    trim = 1 if count >= 6 else 0
    return _ring_slice(dense, first + trim, count - 2 * trim)


def _ring_slice(dense: FloatArray, start: int, count: int) -> FloatArray:
    """``count`` points of the closed ring ``dense`` from index ``start`` on, past its end
    onto its start."""
    n = len(dense)
    start %= n
    if start + count <= n:
        return dense[start : start + count]
    return np.concatenate([dense[start:], dense[: start + count - n]])


def _fit_span(dense: FloatArray, span: Span, vertices: dict[int, list[float]]) -> Line:
    """:func:`_fit_spans` of one span (the same arithmetic, without the batching)."""
    first, last = span
    pts = _span_points(dense, span)
    k = len(pts)
    px, py = pts[:, 0], pts[:, 1]
    cx, cy = math.fsum(px.tolist()) / k, math.fsum(py.tolist()) / k
    dx, dy = px - cx, py - cy
    sums = (
        math.fsum((dx * dx).tolist()),
        math.fsum((dy * dy).tolist()),
        math.fsum((dx * dy).tolist()),
    )
    return _line(cx, cy, sums, vertices[first], vertices[last])


def _line(
    cx: float,
    cy: float,
    sums: tuple[float, float, float],
    start: list[float],
    end: list[float],
) -> Line:
    """The principal axis of centred second moments ``(sxx, syy, sxy)``, pointing from
    ``start`` towards ``end``."""
    sxx, syy, sxy = sums
    angle = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    ux, uy = math.cos(angle), math.sin(angle)
    if ux * (end[0] - start[0]) + uy * (end[1] - start[1]) < 0.0:
        ux, uy = -ux, -uy
    return cx, cy, ux, uy
