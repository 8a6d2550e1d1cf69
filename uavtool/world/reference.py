"""A plain per-triangle z-buffer: slow, obviously right, the oracle for the fast renderer.

Every face (back faces included) is split into a triangle fan; each triangle is tested at
every pixel centre of its bounding box with edge functions (top-left rule on ties) and
perspective-correct depth (1/z interpolated linearly on screen). Tests and
``benchmarks/bench_render.py`` compare :func:`uavtool.world.render` against it.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world.raster import prepare, project_faces
from uavtool.world.render import ImageRGB, _pack, background
from uavtool.world.scene import Scene


def render_reference(scene: Scene, pose: CameraPose, intrinsics: Intrinsics) -> ImageRGB:
    """The same frame as :func:`uavtool.world.render` (without noise), by brute force."""
    prep = prepare(scene)
    buf = background(scene, pose, intrinsics)
    w, h = intrinsics.width_px, intrinsics.height_px
    inv_depth = np.zeros((h, w), dtype=np.float64)
    for sf in project_faces(prep, pose, intrinsics, cull=False):
        color = _pack(prep.face_rgb[sf.face])
        for k in range(1, len(sf.u_px) - 1):
            tri = [(sf.u_px[i], sf.v_px[i], 1.0 / sf.depth_m[i]) for i in (0, k, k + 1)]
            _triangle(tri, color, buf, inv_depth)
    return np.ascontiguousarray(buf.view(np.uint8).reshape(h, w, 4)[:, :, :3])


def _triangle(
    tri: list[tuple[float, float, float]],
    color: np.uint32,
    buf: npt.NDArray[np.uint32],
    inv_depth: npt.NDArray[np.float64],
) -> None:
    (u0, v0, q0), (u1, v1, q1), (u2, v2, q2) = tri
    area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0)
    if area == 0.0:
        return
    if area < 0.0:  # orient so the interior is left of every edge in (u, v)
        (u1, v1, q1), (u2, v2, q2) = (u2, v2, q2), (u1, v1, q1)
        area = -area
    h, w = inv_depth.shape
    c0, c1 = max(math.ceil(min(u0, u1, u2)), 0), min(math.floor(max(u0, u1, u2)) + 1, w)
    r0, r1 = max(math.ceil(min(v0, v1, v2)), 0), min(math.floor(max(v0, v1, v2)) + 1, h)
    if c1 <= c0 or r1 <= r0:
        return
    uu = np.arange(c0, c1, dtype=np.float64)[None, :]
    vv = np.arange(r0, r1, dtype=np.float64)[:, None]
    inside = np.ones((r1 - r0, c1 - c0), dtype=bool)
    weights = []
    for (ua, va), (ub, vb) in (((u1, v1), (u2, v2)), ((u2, v2), (u0, v0)), ((u0, v0), (u1, v1))):
        e = (ub - ua) * (vv - va) - (vb - va) * (uu - ua)  # > 0 left of a→b
        # top-left rule: on an edge, a pixel belongs to the face whose left/top edge it is
        owns_edge = vb < va or (vb == va and ub > ua)
        inside &= (e >= 0.0) if owns_edge else (e > 0.0)
        weights.append(e)
    q = (weights[0] * q0 + weights[1] * q1 + weights[2] * q2) / area
    win = inside & (q > inv_depth[r0:r1, c0:c1])
    np.copyto(inv_depth[r0:r1, c0:c1], q, where=win)
    np.copyto(buf[r0:r1, c0:c1], color, where=win)
