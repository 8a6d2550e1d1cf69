"""How many separate bodies a mesh holds, without trimesh's graph engines (networkx or
SciPy, which uavtool does not install: nothing it runs needs them)."""

from __future__ import annotations

import trimesh


def body_count(mesh: trimesh.Trimesh) -> int:
    """The connected groups of faces, joined where they share a vertex (trimesh merges
    coincident vertices when it builds a mesh)."""
    parent = list(range(len(mesh.vertices)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for face in mesh.faces.tolist():
        a = root(face[0])
        for v in face[1:]:
            b = root(v)
            if a != b:
                parent[b] = a
    return len({root(v) for v in set(mesh.faces.ravel().tolist())})
