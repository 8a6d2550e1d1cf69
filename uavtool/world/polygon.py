"""Plane polygon helpers in plain Python floats: orientation, triangulation, convex pieces.

Everything here is IEEE + − × ÷ on Python floats, so results are identical on every
machine; the renderer and the ground-truth meshes both build on them.
Polygons are sequences of ``(east_m, north_m)`` vertices without a repeated closing vertex.
"""

from __future__ import annotations

from collections.abc import Sequence

Point = tuple[float, float]


def signed_area(ring: Sequence[Point]) -> float:
    """Shoelace area in m²: positive when the ring is counter-clockwise."""
    total = 0.0
    n = len(ring)
    for i in range(n):
        x0, y0 = ring[i]
        x1, y1 = ring[(i + 1) % n]
        total += x0 * y1 - x1 * y0
    return total / 2.0


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def normalise_ring(ring: Sequence[Point]) -> tuple[Point, ...]:
    """Counter-clockwise copy of ``ring`` without a closing duplicate or straight-angle vertices."""
    pts = [(float(x), float(y)) for x, y in ring]
    if len(pts) > 1 and pts[0] == pts[-1]:
        pts.pop()
    changed = True
    while changed and len(pts) > 3:
        changed = False
        for i in range(len(pts)):
            if _cross(pts[i - 1], pts[i], pts[(i + 1) % len(pts)]) == 0.0:
                del pts[i]
                changed = True
                break
    if signed_area(pts) < 0.0:
        pts.reverse()
    return tuple(pts)


def _inside_triangle(p: Point, a: Point, b: Point, c: Point) -> bool:
    return _cross(a, b, p) >= 0.0 and _cross(b, c, p) >= 0.0 and _cross(c, a, p) >= 0.0


def triangulate(ring: Sequence[Point]) -> list[tuple[int, int, int]]:
    """Ear-clipping triangulation of a simple counter-clockwise ring.

    Returns counter-clockwise index triples into ``ring``; O(n³), meant for building
    footprints of a few dozen vertices.
    """
    idx = list(range(len(ring)))
    tris: list[tuple[int, int, int]] = []
    while len(idx) > 3:
        n = len(idx)
        for k in range(n):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % n]
            a, b, c = ring[i0], ring[i1], ring[i2]
            if _cross(a, b, c) <= 0.0:
                continue
            if any(_inside_triangle(ring[j], a, b, c) for j in idx if j not in (i0, i1, i2)):
                continue
            tris.append((i0, i1, i2))
            del idx[k]
            break
        else:  # numerically degenerate remainder: cut the flattest corner
            k = min(
                range(n),
                key=lambda k: abs(_cross(ring[idx[k - 1]], ring[idx[k]], ring[idx[(k + 1) % n]])),
            )
            tris.append((idx[k - 1], idx[k], idx[(k + 1) % n]))
            del idx[k]
    tris.append((idx[0], idx[1], idx[2]))
    return tris


def _is_convex(ring: Sequence[Point], piece: Sequence[int]) -> bool:
    n = len(piece)
    return all(
        _cross(ring[piece[i - 1]], ring[piece[i]], ring[piece[(i + 1) % n]]) >= 0.0
        for i in range(n)
    )


def convex_pieces(ring: Sequence[Point]) -> list[list[int]]:
    """Split a simple counter-clockwise ring into convex counter-clockwise pieces.

    Hertel–Mehlhorn: triangulate, then drop every diagonal whose removal keeps both
    neighbours convex. Returns index lists into ``ring``; a convex ring comes back whole.
    """
    if _is_convex(ring, range(len(ring))):
        return [list(range(len(ring)))]
    pieces: list[list[int]] = [list(t) for t in triangulate(ring)]
    merged = True
    while merged:
        merged = False
        for p in range(len(pieces)):
            for q in range(p + 1, len(pieces)):
                joined = _join(pieces[p], pieces[q])
                if joined is not None and _is_convex(ring, joined):
                    pieces[p] = joined
                    del pieces[q]
                    merged = True
                    break
            if merged:
                break
    return pieces


def _join(a: list[int], b: list[int]) -> list[int] | None:
    """The union of two pieces sharing one edge (a has i→j, b has j→i), else None."""
    na, nb = len(a), len(b)
    for s in range(na):
        i, j = a[s], a[(s + 1) % na]
        for t in range(nb):
            if b[t] == j and b[(t + 1) % nb] == i:
                # walk a from j round to i, then b from i round to j (exclusive of both)
                out = [a[(s + 1 + k) % na] for k in range(na)]
                out += [b[(t + 2 + k) % nb] for k in range(nb - 2)]
                return out
    return None
