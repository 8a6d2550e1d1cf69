"""The ground as the camera sees it: flat areas as spans, and the seeded texture's offsets.

Areas are convex pieces at height 0 projected and covered by the same rules as buildings'
faces (:mod:`uavtool.world.raster`), so they are exact to the pixel and bit-identical across
machines. Nothing on the ground hides a building, so areas are painted over the ground
colour before any building.

The texture is made once per :class:`GroundTexture` as a periodic tile of offsets in world
metres, with box-filtered copies of it ("levels") for pixels that cover many cells (far
ground), so the ground does not shimmer. A frame samples it on a grid of
``TEXTURE_BLOCK_PX`` square blocks: each block takes the cell under its centre's ray, from
the level its ground footprint calls for. Only IEEE + − × ÷ and floor in a fixed order, so
a frame is the same everywhere; the offsets are applied with saturating integer adds.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world.ground import GroundTexture, TextureKind
from uavtool.world.polygon import convex_pieces
from uavtool.world.raster import Prepared, Spans, project_faces, spans_batch
from uavtool.world.scene import RGB, Scene

TEXTURE_BLOCK_PX = 2  # the texture is sampled once per block of this many pixels square
TILE_CELLS = 256  # the tile's side, cells (a power of two)
LEVELS = 8  # levels 0..7 average 1, 2, ... 128 cells square; beyond, the texture is flat
_NOISE_LATTICES = ((8, 0.6), (32, 0.4))  # value-noise lattice spacing (cells) and weight
_NO_IDS = np.zeros(0, dtype=np.int64)
_SHIFT_CELLS = float(TILE_CELLS << 32)  # > any cell index a frame computes, a tile multiple

_MAX_OFFSET = 64  # TEXTURE_AMPLITUDE_DN's upper bound
U32Array = npt.NDArray[np.uint32]


# --------------------------------------------------------------------------- areas


@functools.lru_cache(maxsize=16)
def _areas_prepared(scene: Scene) -> Prepared:
    """The scene's ground areas as upward faces at height 0, cut into convex pieces."""
    verts: list[tuple[float, float, float]] = []
    starts, lens, objs, rgbs = [], [], [], []
    for k, area in enumerate(scene.ground_areas):
        ring = area.polygon_enu_m
        for piece in convex_pieces(ring):
            starts.append(len(verts))
            lens.append(len(piece))
            verts.extend((ring[i][0], ring[i][1], 0.0) for i in piece)
            objs.append(k)
            rgbs.append(area.color_rgb)
    n = len(starts)
    return Prepared(
        verts_enu_m=np.array(verts, dtype=np.float64).reshape(-1, 3),
        face_start=tuple(starts),
        face_len=tuple(lens),
        face_obj=tuple(objs),
        face_rgb=tuple(rgbs),
        normals=np.tile(np.array([0.0, 0.0, 1.0]), (n, 1)),
        offsets=np.zeros(n, dtype=np.float64),
        n_objects=len(scene.ground_areas),
        pair_a=_NO_IDS,
        pair_b=_NO_IDS,
        pair_normal=np.zeros((0, 3), dtype=np.float64),
        pair_offset=np.zeros(0, dtype=np.float64),
        unseparated=frozenset(),
    )


def area_spans(scene: Scene, pose: CameraPose, intr: Intrinsics) -> list[tuple[Spans, RGB]]:
    """Covered pixels and colour of each visible piece of the scene's ground areas, in the
    order they are painted (the scene's order: later areas over earlier ones)."""
    if not scene.ground_areas:
        return []
    prep = _areas_prepared(scene)
    faces = project_faces(prep, pose, intr, cull=True)  # a camera under the ground sees none
    spans = spans_batch(faces, intr.width_px, intr.height_px)
    return [
        (sp, prep.face_rgb[sf.face]) for sf, sp in zip(faces, spans, strict=True) if sp is not None
    ]


# --------------------------------------------------------------------------- texture


@dataclass(frozen=True, slots=True)
class TextureTiles:
    """A texture's offsets (digital numbers, added to every channel): (LEVELS + 1) tiles of
    TILE_CELLS² cells, flattened; the last tile is all zero."""

    cell_m: float
    offsets_dn: npt.NDArray[np.int16]


@dataclass(frozen=True, slots=True)
class TextureFrame:
    """One frame's texture offsets: a value per ``block`` × ``block`` pixels, block row 0
    starting at image row ``row0``; ``offsets_dn`` (rows, cols) int16."""

    offsets_dn: npt.NDArray[np.int16]
    row0: int
    block: int

    def paint(self, rgb: RGB, rows: slice, cols: slice) -> U32Array:
        """Packed pixels of ``rgb`` plus the offsets (saturated to 0–255) for image rows
        ``rows`` and columns ``cols`` (slices with set, increasing bounds, in the ground)."""
        k = self.block
        r0, c0 = (rows.start - self.row0) // k, cols.start // k
        r1, c1 = -(-(rows.stop - self.row0) // k), -(-cols.stop // k)
        big = self._blocks(rgb, r0, r1, c0, c1)
        dr, dc = rows.start - self.row0 - r0 * k, cols.start - c0 * k
        return big[dr : dr + rows.stop - rows.start, dc : dc + cols.stop - cols.start]

    def fill(self, rgb: RGB, out: U32Array) -> None:
        """``out`` (rows ``row0`` on, every column) := :meth:`paint` of them."""
        k = self.block
        rows, cols = self.offsets_dn.shape
        if out.shape == (rows * k, cols * k):  # whole blocks: straight into ``out``
            self._blocks(rgb, 0, rows, 0, cols, out=out)
        else:
            out[...] = self._blocks(rgb, 0, rows, 0, cols)[: out.shape[0], : out.shape[1]]

    def _blocks(
        self, rgb: RGB, r0: int, r1: int, c0: int, c1: int, out: U32Array | None = None
    ) -> U32Array:
        """Blocks ``r0:r1`` × ``c0:c1`` of ``rgb`` plus the offsets, each spread over its
        pixels (OpenCV's nearest resize by a whole factor: copying only)."""
        import cv2  # noqa: PLC0415  # keep `import uavtool.world` light

        small = np.take(_shaded(rgb), self.offsets_dn[r0:r1, c0:c1] + _MAX_OFFSET)
        size = ((c1 - c0) * self.block, (r1 - r0) * self.block)
        dst = None if out is None else out.view(np.int32)
        big = cv2.resize(small.view(np.int32), size, dst=dst, interpolation=cv2.INTER_NEAREST)
        return np.asarray(big).view(np.uint32)


@functools.lru_cache(maxsize=64)
def _shaded(rgb: RGB) -> U32Array:
    """Packed pixels of ``rgb`` plus each offset -_MAX_OFFSET..+_MAX_OFFSET, saturated."""
    off = np.arange(-_MAX_OFFSET, _MAX_OFFSET + 1, dtype=np.int32)[:, None]
    rgba = np.full((off.size, 4), 255, dtype=np.int32)
    rgba[:, :3] = np.clip(np.array(rgb, dtype=np.int32)[None, :] + off, 0, 255)
    return rgba.astype(np.uint8).view(np.uint32).reshape(-1)


@functools.lru_cache(maxsize=8)
def texture_tiles(texture: GroundTexture) -> TextureTiles:
    """The tiles of ``texture`` (made once per texture, ~0.1 s)."""
    n = TILE_CELLS
    rng = np.random.PCG64(texture.seed)  # its raw stream is fixed across numpy versions
    if texture.kind is TextureKind.GRAIN:
        base = _grain(rng, n)
        cell_m = texture.scale_m
    else:
        base = _value_noise(rng, n)
        cell_m = texture.scale_m / _NOISE_LATTICES[0][0]
    levels = [base]
    for k in range(1, LEVELS):
        s, last = 1 << (k - 1), levels[-1]
        rolled = np.roll(last, -s, axis=0)
        levels.append((last + np.roll(last, -s, axis=1) + rolled + np.roll(rolled, -s, 1)) / 4.0)
    offsets = np.rint(np.stack([*levels, np.zeros_like(base)]) * texture.amplitude_dn)
    return TextureTiles(cell_m, offsets.astype(np.int16).reshape(-1))


def _grain(rng: np.random.PCG64, n: int) -> npt.NDArray[np.float64]:
    """(n, n) values in [-1, 1], one per cell: the sum of four random bytes, so they cluster
    about 0 as grain does."""
    raw = rng.random_raw(n * n // 2).astype(np.uint64).view(np.uint8).reshape(-1, 4)
    total = raw.astype(np.int32).sum(axis=1, dtype=np.int32) - 510
    out: npt.NDArray[np.float64] = (total.astype(np.float64) / 510.0).reshape(n, n)
    return out


def _value_noise(rng: np.random.PCG64, n: int) -> npt.NDArray[np.float64]:
    """(n, n) smooth periodic values in [-1, 1]: lattices of random values, interpolated
    bilinearly, weighted and summed."""
    out = np.zeros((n, n), dtype=np.float64)
    for spacing, weight in _NOISE_LATTICES:
        m = n // spacing
        raw = rng.random_raw(m * m).astype(np.uint64)
        lattice = (raw >> np.uint64(11)).astype(np.float64) / float(1 << 52) - 1.0
        lattice = lattice.reshape(m, m)
        f = np.arange(spacing, dtype=np.float64) / spacing  # position between lattice points
        i0 = np.repeat(np.arange(m), spacing)
        i1 = (i0 + 1) % m
        fr = np.tile(f, m)
        rows = lattice[i0] * (1.0 - fr)[:, None] + lattice[i1] * fr[:, None]
        both = rows[:, i0] * (1.0 - fr)[None, :] + rows[:, i1] * fr[None, :]
        out += weight * both
    return out


def texture_frame(
    texture: GroundTexture, pose: CameraPose, intr: Intrinsics, *, first_row: int
) -> TextureFrame | None:
    """The texture's offsets for image rows ``first_row`` on; None when the camera is not
    above the ground (it sees no ground)."""
    cam_x, cam_y, cam_z = (float(p) for p in pose.pos_enu_m)
    h, w = intr.height_px, intr.width_px
    if cam_z <= 0.0 or first_row >= h:
        return None
    tiles = texture_tiles(texture)
    cell = tiles.cell_m
    block = TEXTURE_BLOCK_PX
    right, down, fwd = pose.axes()
    rows, cols = -(-(h - first_row) // block), -(-w // block)
    half = (block - 1) / 2.0
    a = (np.arange(cols, dtype=np.float64) * block + (half - intr.cx_px)) / intr.fx_px
    b = (np.arange(rows, dtype=np.float64) * block + (first_row + half - intr.cy_px)) / intr.fy_px
    # the ray through a block's centre meets the ground at t·(right·a + down·b + fwd)
    dz_row = down[2] * b + fwd[2]
    t_row = np.where(dz_row < 0.0, -cam_z / np.where(dz_row < 0.0, dz_row, -1.0), 0.0)
    # the level: the ground one block spans (across at the centre column, and down it)
    gx = cam_x + t_row * (down[0] * b + fwd[0])
    gy = cam_y + t_row * (down[1] * b + fwd[1])
    step_v = np.zeros_like(gx)
    if len(gx) > 1:
        dx, dy = np.diff(gx), np.diff(gy)
        step_v[:-1] = np.sqrt(dx * dx + dy * dy)
        step_v[-1] = step_v[-2]
    footprint = np.maximum(step_v, t_row * block / intr.fx_px)
    level = np.searchsorted(np.ldexp(cell, np.arange(LEVELS)), footprint, side="left")
    level[t_row <= 0.0] = LEVELS  # sky: the zero tile
    t_row[level == LEVELS] = 0.0  # rows of the zero tile: any cell will do, keep them near
    base = (level * (TILE_CELLS * TILE_CELLS)).astype(np.int64)[:, None]
    if right[2] == 0.0:  # no roll: the ground is at one distance along each row
        t = t_row[:, None]
    else:
        dz = right[2] * a[None, :] + dz_row[:, None]
        t_max = math.ldexp(cell, LEVELS) * intr.fx_px / block  # beyond, a block spans the tile
        ok = (dz < 0.0) & (-cam_z < t_max * dz)
        t = np.where(ok, -cam_z / np.where(ok, dz, -1.0), 0.0)
        base = np.where(ok, base, LEVELS * TILE_CELLS * TILE_CELLS)
    # cells east and north, shifted by a multiple of the tile to be positive: then the
    # integer part is the floor
    x = (t * (right[0] / cell)) * a
    x += _SHIFT_CELLS + (cam_x + t * (down[0] * b + fwd[0])[:, None]) / cell
    y = (t * (right[1] / cell)) * a
    y += _SHIFT_CELLS + (cam_y + t * (down[1] * b + fwd[1])[:, None]) / cell
    mask = TILE_CELLS - 1
    ix = x.astype(np.int64)
    iy = y.astype(np.int64)
    ix &= mask
    iy &= mask
    iy <<= int(math.log2(TILE_CELLS))
    iy |= ix
    iy += base
    return TextureFrame(np.take(tiles.offsets_dn, iy), first_row, block)
