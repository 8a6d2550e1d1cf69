"""Ground truth for evaluation: each building as a watertight mesh and a footprint polygon."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from uavtool.world.polygon import triangulate
from uavtool.world.scene import Block, Building

if TYPE_CHECKING:
    import shapely
    import trimesh


def block_mesh(block: Block) -> trimesh.Trimesh:
    """The block's prism as a watertight mesh with outward normals (ENU metres)."""
    import trimesh  # noqa: PLC0415  # importing trimesh costs ~1 s

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
    return trimesh.Trimesh(
        vertices=np.array(verts, dtype=np.float64),
        faces=np.array(faces, dtype=np.int64),
        process=True,
    )


def building_mesh(building: Building) -> trimesh.Trimesh:
    """The union of the building's blocks: one watertight mesh, through-holes kept."""
    import trimesh  # noqa: PLC0415  # importing trimesh costs ~1 s

    meshes = [block_mesh(b) for b in building.blocks]
    if len(meshes) == 1:
        return meshes[0]
    union: trimesh.Trimesh = trimesh.boolean.union(meshes, engine="manifold")
    return union


def building_footprint(building: Building) -> shapely.Polygon | shapely.MultiPolygon:
    """The building's outline seen from above (the union of its block footprints)."""
    import shapely  # noqa: PLC0415

    return shapely.unary_union([shapely.Polygon(b.footprint_enu_m) for b in building.blocks])
