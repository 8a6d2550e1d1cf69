"""Joining the roofs of one building: seen from above, a building whose blocks have different
heights shows one roof per block, split by a thin strip of wall. Same-coloured shapes closer
than a gap are merged into one outline (a morphological closing of the polygons; what is
left of the wall strips between them, holes thinner than the gap, is filled too). "Same
colour" may allow a few levels per channel: a shape's colour is sampled from a few pixels,
so sensor noise gives two roofs of one building slightly different colours."""

from __future__ import annotations

import numpy as np
import shapely

from uavtool.vision.shapes import Shape


def merge_touching(
    shapes: tuple[Shape, ...], *, gap_px: float, colour_tolerance_dn: float = 0.0
) -> tuple[Shape, ...]:
    """Shapes of one colour less than ``gap_px`` apart become one shape (union closed by
    ``gap_px / 2``, mitred so corners stay sharp). Every shape is closed so, alone or not:
    a wall between two roofs of one building may show as a slit into its outline, or as a
    strip of hole in the roof of the lower block (holes thinner than the gap go too).
    Shapes are returned in order.
    Two colours are one when they differ by at most ``colour_tolerance_dn`` in every RGB
    channel (0–255). The merged shape takes the place and the colour of its first member."""
    if gap_px <= 0.0:
        return shapes
    polys = [shapely.Polygon(s.polygon_px, list(s.holes_px)) for s in shapes]
    group = list(range(len(shapes)))

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for i in range(len(shapes)):
        for j in range(i + 1, len(shapes)):
            if (
                _colour_gap_dn(shapes[i].colour_rgb, shapes[j].colour_rgb) <= colour_tolerance_dn
                and polys[i].distance(polys[j]) < gap_px
            ):
                group[root(j)] = root(i)
    members: dict[int, list[int]] = {}
    for i in range(len(shapes)):
        members.setdefault(root(i), []).append(i)
    out: list[Shape] = []
    for first, idx in sorted(members.items()):
        half = gap_px / 2.0
        union = shapely.union_all([polys[i].buffer(half, join_style="mitre") for i in idx])
        closed = union.buffer(-half, join_style="mitre")
        if not isinstance(closed, shapely.Polygon) or closed.is_empty:
            # did not close into one outline: keep apart
            out.extend(_without_strips(shapes[i], gap_px) for i in idx)
            continue
        if len(idx) == 1 and _same_outline(closed, polys[first]):
            out.append(_without_strips(shapes[first], gap_px))  # nothing to close
            continue
        closed = closed.simplify(0.5, preserve_topology=True)
        holes = [r for r in closed.interiors if not _strip(shapely.Polygon(r), gap_px)]
        out.append(
            Shape.from_rings(
                colour_rgb=shapes[first].colour_rgb,
                polygon_px=np.asarray(closed.exterior.coords[:-1], dtype=np.float64),
                holes_px=tuple(np.asarray(r.coords[:-1], dtype=np.float64) for r in holes),
                cut_by_border=any(shapes[i].cut_by_border for i in idx),
                # the closing may have drawn the outline anywhere across the slits it closed
                detail_px=max(half, *(shapes[i].detail_px for i in idx)),
                left_out_px=max(half, *(shapes[i].left_out_px for i in idx)),
            )
        )
    return tuple(out)


def _same_outline(closed: shapely.Polygon, original: shapely.Polygon) -> bool:
    """Whether ``closed``, a closing of ``original``, has its outer outline, but for
    rounding (a closing only adds: the areas tell)."""
    area = shapely.Polygon(original.exterior).area
    return bool(abs(shapely.Polygon(closed.exterior).area - area) <= 1e-6 * area)


def _strip(hole: shapely.Polygon, gap_px: float) -> bool:
    """A hole thinner on average (twice its area over its perimeter) than the gap: a strip of
    wall between two roofs of one building, not a courtyard."""
    return bool(2.0 * hole.area < gap_px * hole.length)


def _without_strips(shape: Shape, gap_px: float) -> Shape:
    holes = tuple(h for h in shape.holes_px if not _strip(shapely.Polygon(h), gap_px))
    if len(holes) == len(shape.holes_px):
        return shape
    return Shape.from_rings(
        colour_rgb=shape.colour_rgb,
        polygon_px=shape.polygon_px,
        holes_px=holes,
        cut_by_border=shape.cut_by_border,
        detail_px=shape.detail_px,
        left_out_px=shape.left_out_px,
    )


def _colour_gap_dn(a: tuple[int, int, int], b: tuple[int, int, int]) -> int:
    """The largest difference of two RGB colours in one channel."""
    return max(abs(a[0] - b[0]), abs(a[1] - b[1]), abs(a[2] - b[2]))
