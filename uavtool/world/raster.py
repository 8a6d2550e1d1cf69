"""Scene geometry as camera-ready faces, and exact pixel-centre coverage of convex polygons.

Shared by the fast renderer (:mod:`uavtool.world.render`) and the reference z-buffer
(:mod:`uavtool.world.reference`) so both see exactly the same projected polygons.

Coverage rule: pixel ``(i, j)`` (centre ``u = i, v = j``) belongs to a polygon when its
centre is inside; on an edge it belongs to the face whose left or top edge it is (the usual
top-left rule), so faces that share an edge neither overlap nor leave a crack.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world.polygon import convex_pieces
from uavtool.world.scene import Scene

NEAR_M = 0.05  # faces are clipped this far in front of the camera
_TOUCH_M = 1e-9

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Prepared:
    """A scene cut into convex prisms ("objects") and their outward faces.

    verts_enu_m : (n, 3) float — every face's vertices, face after face.
    normals : (f, 3) float — outward unit normal per face; ``offsets`` (f,) with n·x = d.
    pair_* : separating planes of object pairs; object ``pair_a`` lies where n·x ≤ d.
    """

    verts_enu_m: FloatArray
    face_start: tuple[int, ...]
    face_len: tuple[int, ...]
    face_obj: tuple[int, ...]
    face_rgb: tuple[tuple[int, int, int], ...]
    normals: FloatArray
    offsets: FloatArray
    n_objects: int
    pair_a: IntArray
    pair_b: IntArray
    pair_normal: FloatArray
    pair_offset: FloatArray
    unseparated: frozenset[tuple[int, int]]


@dataclass(frozen=True, slots=True)
class Prism:
    footprint: tuple[tuple[float, float], ...]
    base_m: float
    top_m: float


def shade(
    rgb: tuple[int, int, int], normal: tuple[float, float, float], scene: Scene
) -> tuple[int, int, int]:
    """Flat colour of a face: the same factor on all channels keeps the hue."""
    light = scene.lighting
    az, el = math.radians(light.sun_azimuth_deg), math.radians(light.sun_elevation_deg)
    sun = (math.cos(el) * math.sin(az), math.cos(el) * math.cos(az), math.sin(el))
    lambert = max(0.0, normal[0] * sun[0] + normal[1] * sun[1] + normal[2] * sun[2])
    factor = light.ambient + (1.0 - light.ambient) * lambert
    r, g, b = (min(255, math.floor(c * factor + 0.5)) for c in rgb)
    return (r, g, b)


@functools.lru_cache(maxsize=16)
def prepare(scene: Scene) -> Prepared:
    """Cut every block into convex prisms and list their faces (cached per scene)."""
    verts: list[tuple[float, float, float]] = []
    starts: list[int] = []
    lens: list[int] = []
    objs: list[int] = []
    rgbs: list[tuple[int, int, int]] = []
    normals: list[tuple[float, float, float]] = []
    offsets: list[float] = []
    prisms: list[Prism] = []

    def add(
        poly: list[tuple[float, float, float]],
        n: tuple[float, float, float],
        rgb: tuple[int, int, int],
    ) -> None:
        starts.append(len(verts))
        lens.append(len(poly))
        verts.extend(poly)
        objs.append(len(prisms) - 1)
        rgbs.append(shade(rgb, n, scene))
        normals.append(n)
        offsets.append(n[0] * poly[0][0] + n[1] * poly[0][1] + n[2] * poly[0][2])

    for building in scene.buildings:
        for block in building.blocks:
            ring = block.footprint_enu_m
            n_ring = len(ring)
            for piece in convex_pieces(ring):
                pts = tuple(ring[k] for k in piece)
                prisms.append(Prism(pts, block.base_m, block.top_m))
                lo, hi = block.base_m, block.top_m
                add([(x, y, hi) for x, y in pts], (0.0, 0.0, 1.0), building.color_rgb)
                if lo > 0.0:
                    add(
                        [(x, y, lo) for x, y in reversed(pts)], (0.0, 0.0, -1.0), building.color_rgb
                    )
                for k in range(len(piece)):
                    ia, ib = piece[k], piece[(k + 1) % len(piece)]
                    if ib != (ia + 1) % n_ring:
                        continue  # an internal diagonal, not a wall
                    (xa, ya), (xb, yb) = ring[ia], ring[ib]
                    length = math.sqrt((xb - xa) * (xb - xa) + (yb - ya) * (yb - ya))
                    n = ((yb - ya) / length, -(xb - xa) / length, 0.0)
                    add(
                        [(xa, ya, lo), (xb, yb, lo), (xb, yb, hi), (xa, ya, hi)],
                        n,
                        building.color_rgb,
                    )

    pa, pb, pn, pd = [], [], [], []
    unseparated: set[tuple[int, int]] = set()
    for i in range(len(prisms)):
        for j in range(i + 1, len(prisms)):
            plane = separating_plane(prisms[i], prisms[j])
            if plane is None:
                unseparated.add((i, j))
                continue
            pa.append(i)
            pb.append(j)
            pn.append(plane[0])
            pd.append(plane[1])
    return Prepared(
        verts_enu_m=np.array(verts, dtype=np.float64).reshape(-1, 3),
        face_start=tuple(starts),
        face_len=tuple(lens),
        face_obj=tuple(objs),
        face_rgb=tuple(rgbs),
        normals=np.array(normals, dtype=np.float64).reshape(-1, 3),
        offsets=np.array(offsets, dtype=np.float64),
        n_objects=len(prisms),
        pair_a=np.array(pa, dtype=np.int64),
        pair_b=np.array(pb, dtype=np.int64),
        pair_normal=np.array(pn, dtype=np.float64).reshape(-1, 3),
        pair_offset=np.array(pd, dtype=np.float64),
        unseparated=frozenset(unseparated),
    )


def separating_plane(a: Prism, b: Prism) -> tuple[tuple[float, float, float], float] | None:
    """A plane n·x = d with ``a`` on the side n·x ≤ d and ``b`` on n·x ≥ d, or None."""
    if a.top_m <= b.base_m:
        return (0.0, 0.0, 1.0), a.top_m
    if b.top_m <= a.base_m:
        return (0.0, 0.0, -1.0), -a.base_m
    # Two convex footprints that do not overlap are split by the line through an edge of one.
    for poly, other, flip in ((a.footprint, b.footprint, 1.0), (b.footprint, a.footprint, -1.0)):
        for k in range(len(poly)):
            (xa, ya), (xb, yb) = poly[k], poly[(k + 1) % len(poly)]
            mx, my = yb - ya, -(xb - xa)  # outward for a counter-clockwise footprint
            scale = math.sqrt(mx * mx + my * my)
            mx, my = mx / scale, my / scale
            d = mx * xa + my * ya
            if all(mx * x + my * y >= d - _TOUCH_M for x, y in other):
                return (flip * mx, flip * my, 0.0), flip * d
    return None


# --------------------------------------------------------------------------- projection


@dataclass(frozen=True, slots=True)
class ScreenFace:
    """A face clipped to the near plane and projected: pixel polygon and camera-space plane."""

    face: int
    u_px: tuple[float, ...]
    v_px: tuple[float, ...]
    depth_m: tuple[float, ...]


def project_faces(
    prep: Prepared, pose: CameraPose, intr: Intrinsics, *, cull: bool
) -> list[ScreenFace]:
    """Faces in front of the camera as pixel polygons; ``cull`` drops faces seen from behind.

    Only IEEE + − × ÷ in a fixed order, so the same pose gives the same pixels everywhere.
    """
    rot = pose.world_from_camera()
    cx, cy, cz = (float(p) for p in pose.pos_enu_m)
    rel = prep.verts_enu_m - np.array([cx, cy, cz])
    cam = [rel[:, 0] * rot[0, k] + rel[:, 1] * rot[1, k] + rel[:, 2] * rot[2, k] for k in range(3)]
    xs, ys, zs = (c.tolist() for c in cam)
    nrm = prep.normals
    side = (nrm[:, 0] * cx + nrm[:, 1] * cy + nrm[:, 2] * cz - prep.offsets).tolist()
    fx, fy, ccx, ccy = intr.fx_px, intr.fy_px, intr.cx_px, intr.cy_px
    out: list[ScreenFace] = []
    for f, start in enumerate(prep.face_start):
        if cull and side[f] <= 0.0:
            continue
        stop = start + prep.face_len[f]
        poly = list(zip(xs[start:stop], ys[start:stop], zs[start:stop], strict=True))
        if min(p[2] for p in poly) < NEAR_M:
            poly = _clip_near(poly)
            if len(poly) < 3:
                continue
        out.append(
            ScreenFace(
                f,
                tuple(fx * x / z + ccx for x, _, z in poly),
                tuple(fy * y / z + ccy for _, y, z in poly),
                tuple(z for _, _, z in poly),
            )
        )
    return out


def _clip_near(poly: list[tuple[float, float, float]]) -> list[tuple[float, float, float]]:
    """Sutherland–Hodgman against z ≥ NEAR_M; the crossing is always computed inside→outside."""
    out: list[tuple[float, float, float]] = []
    n = len(poly)
    for k in range(n):
        p, q = poly[k], poly[(k + 1) % n]
        p_in, q_in = p[2] >= NEAR_M, q[2] >= NEAR_M
        if p_in:
            out.append(p)
        if p_in != q_in:
            i, o = (p, q) if p_in else (q, p)
            t = (NEAR_M - i[2]) / (o[2] - i[2])
            out.append((i[0] + t * (o[0] - i[0]), i[1] + t * (o[1] - i[1]), NEAR_M))
    return out


# --------------------------------------------------------------------------- coverage


@dataclass(frozen=True, slots=True)
class Spans:
    """Covered pixels of one face: row ``row0 + k`` covers columns ``[left[k], right[k])``."""

    row0: int
    left: IntArray
    right: IntArray
    col0: int
    col1: int


def spans_batch(faces: list[ScreenFace], width: int, height: int) -> list[Spans | None]:
    """Pixel-centre coverage of convex faces, clipped to the image; None where empty.

    Each edge is evaluated from its lower endpoint, so two faces sharing an edge get
    bit-identical bounds; all faces' rows are computed in one vectorised pass.
    """
    edges_ua: list[list[float]] = []
    edges_va: list[list[float]] = []
    edges_slope: list[list[float]] = []
    edges_kind: list[list[int]] = []
    row_ranges: list[tuple[int, int]] = []
    for sf in faces:
        u_px, v_px = sf.u_px, sf.v_px
        n = len(u_px)
        area2 = 0.0
        for k in range(n):
            area2 += u_px[k] * v_px[(k + 1) % n] - u_px[(k + 1) % n] * v_px[k]
        ua_l: list[float] = []
        va_l: list[float] = []
        sl_l: list[float] = []
        kind_l: list[int] = []
        row0 = row1 = 0
        if area2 != 0.0 and not math.isnan(area2):
            if area2 < 0.0:
                u_px, v_px = u_px[::-1], v_px[::-1]
            row0 = max(math.ceil(min(v_px)), 0)
            row1 = min(math.ceil(max(v_px)), height)
            for k in range(n):
                u0, v0, u1, v1 = u_px[k], v_px[k], u_px[(k + 1) % n], v_px[(k + 1) % n]
                if v1 == v0:
                    continue
                ua, va, ub, vb = (u0, v0, u1, v1) if (v0, u0) < (v1, u1) else (u1, v1, u0, v0)
                ua_l.append(ua)
                va_l.append(va)
                sl_l.append((ub - ua) / (vb - va))
                kind_l.append(1 if v1 > v0 else -1)
        row_ranges.append((row0, max(row1, row0)))
        edges_ua.append(ua_l)
        edges_va.append(va_l)
        edges_slope.append(sl_l)
        edges_kind.append(kind_l)
    n_rows = [r1 - r0 for r0, r1 in row_ranges]
    total = sum(n_rows)
    out: list[Spans | None] = [None] * len(faces)
    if total == 0:
        return out
    e_max = max(len(k) for k in edges_kind)
    n_faces = len(faces)
    a_ua = np.zeros((n_faces, e_max))
    a_va = np.zeros((n_faces, e_max))
    a_slope = np.zeros((n_faces, e_max))
    a_kind = np.zeros((n_faces, e_max), dtype=np.int8)
    for f in range(n_faces):
        m = len(edges_kind[f])
        a_ua[f, :m] = edges_ua[f]
        a_va[f, :m] = edges_va[f]
        a_slope[f, :m] = edges_slope[f]
        a_kind[f, :m] = edges_kind[f]
    face_of_row = np.repeat(np.arange(n_faces), n_rows)
    starts = np.cumsum([0, *n_rows])
    rows = np.arange(total, dtype=np.int64) - np.repeat(starts[:-1], n_rows)
    rows += np.repeat(np.array([r0 for r0, _ in row_ranges], dtype=np.int64), n_rows)
    x = (
        a_ua[face_of_row]
        + (rows.astype(np.float64)[:, None] - a_va[face_of_row]) * a_slope[face_of_row]
    )
    a_k = a_kind[face_of_row]
    left = np.where(a_k < 0, x, -np.inf).max(axis=1)
    right = np.where(a_k > 0, x, np.inf).min(axis=1)
    il = np.clip(np.ceil(left), 0, width).astype(np.int64)
    ir = np.clip(np.ceil(right), 0, width).astype(np.int64)
    filled = il < ir
    lo = np.where(filled, il, width)
    hi = np.where(filled, ir, 0)
    for f in range(n_faces):
        a, b = int(starts[f]), int(starts[f + 1])
        if b == a:
            continue
        col0, col1 = int(lo[a:b].min()), int(hi[a:b].max())
        if col1 <= col0:
            continue
        out[f] = Spans(row_ranges[f][0], il[a:b], ir[a:b], col0, col1)
    return out


def inverse_depth_plane(
    face: int, prep: Prepared, pose: CameraPose, intr: Intrinsics
) -> tuple[float, float, float]:
    """(a, b, c) with 1/depth = a·u + b·v + c over the face's plane (depth along the axis)."""
    rot = pose.world_from_camera()
    n = prep.normals[face]
    nc = [float(n[0] * rot[0, k] + n[1] * rot[1, k] + n[2] * rot[2, k]) for k in range(3)]
    px, py, pz = (float(p) for p in pose.pos_enu_m)
    dc = float(prep.offsets[face]) - (float(n[0]) * px + float(n[1]) * py + float(n[2]) * pz)
    a = nc[0] / (intr.fx_px * dc)
    b = nc[1] / (intr.fy_px * dc)
    c = (nc[2] - nc[0] * intr.cx_px / intr.fx_px - nc[1] * intr.cy_px / intr.fy_px) / dc
    return a, b, c


def ground_rows(pose: CameraPose, intr: Intrinsics) -> int:
    """Index of the first image row that sees the ground (rows above it see the sky)."""
    if pose.roll_deg != 0.0:
        return _ground_rows_rolled(pose, intr)
    p = math.radians(pose.pitch_deg)
    sp, cp = math.sin(p), math.cos(p)
    # a pixel row looks down when  -cos(p)·(v - cy)/fy + sin(p) < 0
    for_row = [(-cp * (j - intr.cy_px) / intr.fy_px + sp) < 0.0 for j in range(intr.height_px)]
    return for_row.index(True) if True in for_row else intr.height_px


def _ground_rows_rolled(pose: CameraPose, intr: Intrinsics) -> int:
    """:func:`ground_rows` for a rolled camera: the first row either of whose end pixels
    looks down (the horizon is a straight line across the image)."""
    right, down, forward = pose.axes()
    for j in range(intr.height_px):
        y = (j - intr.cy_px) / intr.fy_px
        for i in (0, intr.width_px - 1):
            x = (i - intr.cx_px) / intr.fx_px
            if x * right[2] + y * down[2] + forward[2] < 0.0:
                return j
    return intr.height_px


def paint_polygon(
    image: npt.NDArray[np.generic], pts_px: FloatArray, value: int | tuple[int, ...]
) -> None:
    """Paint the simple polygon ``pts_px`` ``(n, 2)`` (``u, v`` pixels, any winding, convex
    or not) into ``image`` in place by the coverage rule above: a pixel whose centre is
    inside (even-odd, a vertex's row counted once). OpenCV's ``fillPoly`` also paints every
    pixel its edges pass through, which grows a shape by half a pixel all round; pictures
    drawn for measuring outlines against the polygon they were drawn from use this."""
    u0 = np.asarray(pts_px, dtype=np.float64)[:, 0]
    v0 = np.asarray(pts_px, dtype=np.float64)[:, 1]
    u1, v1 = np.roll(u0, -1), np.roll(v0, -1)
    height, width = image.shape[:2]
    crossings: list[tuple[int, float]] = []
    for au, av, bu, bv in zip(u0.tolist(), v0.tolist(), u1.tolist(), v1.tolist(), strict=True):
        if av == bv:
            continue
        lo, hi = (av, bv) if av < bv else (bv, av)
        rows = np.arange(max(math.ceil(lo), 0), min(math.ceil(hi), height))
        us = au + (rows - av) * (bu - au) / (bv - av)
        crossings += zip(rows.tolist(), us.tolist(), strict=True)
    crossings.sort()
    for (row, left), (_, right) in zip(crossings[::2], crossings[1::2], strict=True):
        c0, c1 = max(math.ceil(left), 0), min(math.ceil(right), width)
        if c1 > c0:
            image[row, c0:c1] = value
