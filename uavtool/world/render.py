"""The deterministic software camera: exact visibility without a per-pixel depth buffer.

Every block is cut into convex prisms. Seen from one point, the front faces of a convex
prism never overlap, and two disjoint convex prisms are split by a plane, so the prism on
the camera's side of that plane is never hidden by the other. Sorting the prisms by those
planes (computed once per scene; only the camera's side changes per frame) gives an exact
back-to-front order, and painting faces in it gives the z-buffer's image at a fraction of
the cost. If the order has a cycle, the frame falls back to a per-pixel depth test.

Coverage is the pixel-centre rule of :mod:`uavtool.world.raster`, computed with IEEE
arithmetic in a fixed order and filled with integer spans, so a frame is bit-identical
across machines and numpy/OpenCV versions.
"""

from __future__ import annotations

import heapq

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world.ground_render import area_spans, texture_frame
from uavtool.world.raster import (
    Prepared,
    ScreenFace,
    Spans,
    ground_rows,
    inverse_depth_plane,
    prepare,
    project_faces,
    spans_batch,
)
from uavtool.world.scene import Scene

ImageRGB = npt.NDArray[np.uint8]
NOISE_STD_DN = 3.0  # default sensor noise, digital numbers (0–255 scale)


def render(
    scene: Scene,
    pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    noise_seed: int | None = None,
    noise_std_dn: float = NOISE_STD_DN,
) -> ImageRGB:
    """The camera image of ``scene`` from ``pose``: (H, W, 3) uint8 RGB.

    With ``noise_seed`` set, seeded zero-mean sensor noise of about ``noise_std_dn`` is
    added; the same seed gives the same image.
    """
    rgb = rgb_from_packed(render_packed(scene, pose, intrinsics))
    if noise_seed is not None:
        add_noise(rgb, seed=noise_seed, std_dn=noise_std_dn)
    return rgb


def rgb_from_packed(packed: npt.NDArray[np.uint32]) -> ImageRGB:
    """(H, W, 3) uint8 RGB from packed RGBA pixels (a plain byte copy)."""
    import cv2  # noqa: PLC0415  # keep `import uavtool.world` light

    rgba = packed.view(np.uint8).reshape(*packed.shape, 4)
    return np.asarray(cv2.cvtColor(rgba, cv2.COLOR_RGBA2RGB), dtype=np.uint8)


def _pack(rgb: tuple[int, int, int]) -> np.uint32:
    """One packed pixel whose bytes in memory are R, G, B, 255 on any byte order."""
    return np.uint32(np.array([rgb[0], rgb[1], rgb[2], 255], dtype=np.uint8).view(np.uint32)[0])


def background(scene: Scene, pose: CameraPose, intrinsics: Intrinsics) -> npt.NDArray[np.uint32]:
    """Sky above the horizon, ground below with its areas and texture, as packed RGBA (H, W)
    uint32: what every building is painted over (nothing on the ground hides one)."""
    h, w = intrinsics.height_px, intrinsics.width_px
    buf = np.empty((h, w), dtype=np.uint32)
    horizon = ground_rows(pose, intrinsics)
    buf[:horizon] = _pack(scene.sky_rgb)
    texture = None
    if scene.ground_texture is not None:
        texture = texture_frame(scene.ground_texture, pose, intrinsics, first_row=horizon)
    if texture is None:
        buf[horizon:] = _pack(scene.ground_rgb)
    else:
        texture.fill(scene.ground_rgb, buf[horizon:])
    if scene.ground_areas:
        cols = np.arange(w, dtype=np.int64)
        for sp, rgb in area_spans(scene, pose, intrinsics):
            rows = slice(sp.row0, sp.row0 + len(sp.left))
            where = buf[rows, sp.col0 : sp.col1]
            if texture is None:
                np.copyto(where, _pack(rgb), where=_mask(sp, cols))
            else:
                colour = texture.paint(rgb, rows, slice(sp.col0, sp.col1))
                np.copyto(where, colour, where=_mask(sp, cols))
    return buf


def render_packed(
    scene: Scene, pose: CameraPose, intrinsics: Intrinsics, *, force_depth_test: bool = False
) -> npt.NDArray[np.uint32]:
    """The frame as packed RGBA (H, W) uint32 (byte order R, G, B, A in memory)."""
    prep = prepare(scene)
    buf = background(scene, pose, intrinsics)
    w, h = intrinsics.width_px, intrinsics.height_px
    faces = project_faces(prep, pose, intrinsics, cull=True)
    drawn = [
        (sf, sp) for sf, sp in zip(faces, spans_batch(faces, w, h), strict=True) if sp is not None
    ]
    order = None if force_depth_test else _object_order(prep, pose, drawn)
    cols = np.arange(w, dtype=np.int64)
    if order is not None:
        rank = {obj: k for k, obj in enumerate(order)}
        drawn.sort(key=lambda item: rank[prep.face_obj[item[0].face]])
        for sf, sp in drawn:
            mask = _mask(sp, cols)
            np.copyto(
                buf[sp.row0 : sp.row0 + len(sp.left), sp.col0 : sp.col1],
                _pack(prep.face_rgb[sf.face]),
                where=mask,
            )
        return buf
    _depth_tested(prep, pose=pose, intr=intrinsics, drawn=drawn, buf=buf, cols=cols)
    return buf


def _mask(sp: Spans, cols: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
    c = cols[sp.col0 : sp.col1]
    mask = c >= sp.left[:, None]
    mask &= c < sp.right[:, None]
    return mask


def _object_order(
    prep: Prepared, pose: CameraPose, drawn: list[tuple[ScreenFace, Spans]]
) -> list[int] | None:
    """Back-to-front order of the visible objects, or None if their order has a cycle."""
    boxes: dict[int, tuple[int, int, int, int]] = {}
    for sf, sp in drawn:
        obj = prep.face_obj[sf.face]
        r0, r1, c0, c1 = sp.row0, sp.row0 + len(sp.left), sp.col0, sp.col1
        if obj in boxes:
            o = boxes[obj]
            r0, r1, c0, c1 = min(o[0], r0), max(o[1], r1), min(o[2], c0), max(o[3], c1)
        boxes[obj] = (r0, r1, c0, c1)
    if len(boxes) < 2:
        return list(boxes)
    cx, cy, cz = (float(p) for p in pose.pos_enu_m)
    nrm = prep.pair_normal
    side = (nrm[:, 0] * cx + nrm[:, 1] * cy + nrm[:, 2] * cz - prep.pair_offset).tolist()
    after: dict[int, list[int]] = {obj: [] for obj in boxes}
    indegree = dict.fromkeys(boxes, 0)
    for a, b, s in zip(prep.pair_a.tolist(), prep.pair_b.tolist(), side, strict=True):
        if s == 0.0 or a not in boxes or b not in boxes:
            continue
        ba, bb = boxes[a], boxes[b]
        if ba[0] >= bb[1] or bb[0] >= ba[1] or ba[2] >= bb[3] or bb[2] >= ba[3]:
            continue  # their pixels cannot meet
        first, second = (a, b) if s > 0.0 else (b, a)  # the camera sees `second` in front
        after[first].append(second)
        indegree[second] += 1
    for a, b in prep.unseparated:
        if a in boxes and b in boxes:
            return None
    ready = [obj for obj, d in indegree.items() if d == 0]
    heapq.heapify(ready)
    order: list[int] = []
    while ready:
        obj = heapq.heappop(ready)
        order.append(obj)
        for nxt in after[obj]:
            indegree[nxt] -= 1
            if indegree[nxt] == 0:
                heapq.heappush(ready, nxt)
    return order if len(order) == len(boxes) else None


def _depth_tested(
    prep: Prepared,
    *,
    pose: CameraPose,
    intr: Intrinsics,
    drawn: list[tuple[ScreenFace, Spans]],
    buf: npt.NDArray[np.uint32],
    cols: npt.NDArray[np.int64],
) -> None:
    """Per-pixel inverse-depth test, face by face (the slow path for cyclic overlaps)."""
    inv_depth = np.zeros(buf.shape, dtype=np.float64)
    colsf = cols.astype(np.float64)
    for sf, sp in drawn:
        a, b, c = inverse_depth_plane(sf.face, prep, pose, intr)
        r0, r1 = sp.row0, sp.row0 + len(sp.left)
        rows = np.arange(r0, r1, dtype=np.float64)
        plane = (rows * b + c)[:, None] + colsf[None, sp.col0 : sp.col1] * a
        zslice = inv_depth[r0:r1, sp.col0 : sp.col1]
        win = _mask(sp, cols)
        win &= plane > zslice
        np.copyto(zslice, plane, where=win)
        np.copyto(buf[r0:r1, sp.col0 : sp.col1], _pack(prep.face_rgb[sf.face]), where=win)


def add_noise(rgb: ImageRGB, *, seed: int, std_dn: float = NOISE_STD_DN) -> None:
    """Add seeded, zero-mean, roughly Gaussian noise in place.

    Built from the raw PCG64 stream (whose output numpy guarantees across versions) as
    the sum of four uniform bytes, so the result depends on nothing but integer arithmetic.
    """
    n = rgb.size
    raw = np.random.PCG64(seed).random_raw((n + 1) // 2).astype(np.uint64)
    bytes_ = raw.view(np.uint8)[: 8 * ((n + 1) // 2)].reshape(-1, 4)[:n]
    total = bytes_.astype(np.int32).sum(axis=1, dtype=np.int32) - 510  # std ≈ 147.8
    scale = np.float32(std_dn / 147.80138)
    noise = np.rint(total.astype(np.float32) * scale).astype(np.int16)
    out = rgb.reshape(-1).astype(np.int16) + noise
    np.clip(out, 0, 255, out=out)
    rgb.reshape(-1)[:] = out.astype(np.uint8)
