"""A triangle mesh as binary glTF (GLB): what recordings and ``uavtool vision model`` write
for a 3D model, and what Foxglove's, Lichtblick's and Rerun's 3D views load.

trimesh (~0.1 s to import) and numpy are imported only when a mesh is encoded: the mission
and its replay handle vertices and faces alone, and a recording's writer process (which has
no numpy otherwise) encodes the mesh off the flight's path.
"""

from __future__ import annotations

from typing import Any


def mesh_glb(vertices_m: Any, faces: Any) -> bytes:
    """``vertices_m`` ``(n, 3)`` and ``faces`` ``(m, 3)`` (indices, counter-clockwise seen
    from outside; arrays or nested sequences) as GLB bytes, shaded as flat light-grey faces.

    Each face gets its own vertices and their normal, and the mesh a matte material:
    viewers built on three.js (Foxglove's and Lichtblick's 3D panels) compute no normals for
    a glTF mesh that has none and draw it black."""
    import numpy as np  # noqa: PLC0415 — see the module's docstring
    import trimesh  # noqa: PLC0415

    m = trimesh.Trimesh(
        vertices=np.asarray(vertices_m, dtype=np.float64).reshape(-1, 3),
        faces=np.asarray(faces, dtype=np.int64).reshape(-1, 3),
        process=False,
    )
    visual: Any = trimesh.visual  # its constructors are untyped
    matte = visual.material.PBRMaterial(
        name="model", baseColorFactor=[190, 190, 190, 255], metallicFactor=0.0, roughnessFactor=1.0
    )
    mesh = trimesh.Trimesh(
        vertices=m.vertices[m.faces].reshape(-1, 3),
        faces=np.arange(3 * len(m.faces)).reshape(-1, 3),
        vertex_normals=np.repeat(m.face_normals, 3, axis=0),
        visual=visual.TextureVisuals(material=matte),
        process=False,
    )
    data = mesh.export(file_type="glb", include_normals=True)
    if not isinstance(data, bytes):  # trimesh returns bytes for binary formats
        raise TypeError(f"trimesh returned {type(data).__name__} for GLB")
    return data
