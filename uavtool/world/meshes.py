"""Ground truth for evaluation: each building as a watertight mesh and a footprint polygon."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from uavtool.world.polygon import triangulate
from uavtool.world.scene import Block, Building

if TYPE_CHECKING:
    import shapely
    import trimesh


def block_mesh(block: Block) -> trimesh.Trimesh:
    """The block's prism as a watertight mesh with outward normals (ENU metres)."""
    import trimesh  # noqa: PLC0415  # importing trimesh costs ~0.1 s

    verts, faces = _block_arrays(block)
    return trimesh.Trimesh(vertices=verts, faces=faces, process=True)


def building_mesh(building: Building) -> trimesh.Trimesh:
    """The union of the building's blocks: one watertight mesh, through-holes kept."""
    import trimesh  # noqa: PLC0415  # importing trimesh costs ~0.1 s

    meshes = [block_mesh(b) for b in building.blocks]
    if len(meshes) == 1:
        return meshes[0]
    union: trimesh.Trimesh = trimesh.boolean.union(meshes, engine="manifold")
    return union


def building_solid(building: Building) -> Any:
    """The union of the building's blocks as a ``manifold3d.Manifold`` (what trimesh's union
    computes in :func:`building_mesh`, without importing trimesh)."""
    import manifold3d  # noqa: PLC0415

    solids = []
    for block in building.blocks:
        verts, faces = _block_arrays(block)
        mesh = manifold3d.Mesh(verts.astype(np.float32), faces.astype(np.uint32))
        solids.append(manifold3d.Manifold(mesh))
    if len(solids) == 1:
        return solids[0]
    return manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add)


def _block_arrays(block: Block) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """The block's prism: vertices (floor ring, then roof ring) and faces with outward normals."""
    ring = block.footprint_enu_m
    n = len(ring)
    verts = [(x, y, block.base_m) for x, y in ring] + [(x, y, block.top_m) for x, y in ring]
    faces: list[tuple[int, int, int]] = []
    for a, b, c in triangulate(ring):
        faces.append((a + n, b + n, c + n))  # roof, counter-clockwise seen from above
        faces.append((c, b, a))  # floor, facing down
    for k in range(n):
        j = (k + 1) % n
        faces.append((k, j, j + n))
        faces.append((k, j + n, k + n))
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def building_footprint(building: Building) -> shapely.Polygon | shapely.MultiPolygon:
    """The building's outline seen from above (the union of its block footprints)."""
    import shapely  # noqa: PLC0415

    return shapely.unary_union([shapely.Polygon(b.footprint_enu_m) for b in building.blocks])
