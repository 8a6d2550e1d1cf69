"""A triangle mesh as binary glTF 2.0 (GLB): what recordings and ``uavtool vision model`` write
for a 3D model, and what Foxglove's, Lichtblick's and Rerun's 3D views load.

Written here, with numpy alone, rather than by trimesh: one flat-shaded mesh needs a few
dozen lines of the format (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html), and
importing trimesh costs ~0.5 G instructions (~0.15 s), which a recording's writer process
paid in every flight, beside the flight. numpy is imported only when a mesh is encoded: the
mission and its replay handle vertices and faces alone.
"""

from __future__ import annotations

import json
import struct
from typing import Any

# glTF's constants: the chunk types, a primitive of triangles, component types
_GLTF, _JSON, _BIN = 0x46546C67, 0x4E4F534A, 0x004E4942
_TRIANGLES, _UINT32, _FLOAT32 = 4, 5125, 5126
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963  # what a buffer view holds: vertices, indices
_GREY = 190 / 255  # the model's matte light grey


def mesh_glb(vertices_m: Any, faces: Any) -> bytes:
    """``vertices_m`` ``(n, 3)`` and ``faces`` ``(m, 3)`` (indices, counter-clockwise seen
    from outside; arrays or nested sequences) as GLB bytes, shaded as flat light-grey faces.

    Each face gets its own three vertices and its unit normal, and the mesh a matte material:
    viewers built on three.js (Foxglove's and Lichtblick's 3D panels) compute no normals for
    a glTF mesh that has none and draw it black. Faces without area are left out: they draw
    nothing, and glTF has no normal for them.

    Raises ValueError for a face index out of range, a vertex not finite, or no face with an
    area."""
    import numpy as np  # noqa: PLC0415 — see the module's docstring

    vertices = np.asarray(vertices_m, dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(tri) and (tri.min() < 0 or tri.max() >= len(vertices)):
        raise ValueError(f"a face index is outside the mesh's {len(vertices)} vertices")
    if not np.isfinite(vertices).all():
        raise ValueError("a mesh's vertex is not a finite point")
    corners = vertices[tri]  # (m, 3, 3)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    drawn = length[:, 0] > 0  # a face without area draws nothing and has no normal
    if not drawn.any():
        raise ValueError("a GLB mesh needs a face with an area; this one has none")
    corners, normals = corners[drawn], normals[drawn] / length[drawn]
    count = 3 * len(corners)
    indices = np.arange(count, dtype="<u4")
    positions = corners.reshape(-1, 3).astype("<f4")
    per_vertex = np.repeat(normals, 3, axis=0).astype("<f4")
    views = [indices.tobytes(), positions.tobytes(), per_vertex.tobytes()]  # each 4-aligned
    offsets = np.cumsum([0] + [len(v) for v in views]).tolist()

    def vec3(view: int, values: Any) -> dict[str, Any]:
        return {
            "bufferView": view,
            "componentType": _FLOAT32,
            "count": count,
            "type": "VEC3",
            "min": values.min(axis=0).tolist(),
            "max": values.max(axis=0).tolist(),
        }

    gltf = {
        "asset": {"version": "2.0", "generator": "uavtool"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "model", "mesh": 0}],
        "meshes": [
            {
                "name": "model",
                "primitives": [
                    {
                        "attributes": {"POSITION": 1, "NORMAL": 2},
                        "indices": 0,
                        "material": 0,
                        "mode": _TRIANGLES,
                    }
                ],
            }
        ],
        "materials": [
            {
                "name": "model",
                "pbrMetallicRoughness": {
                    "baseColorFactor": [_GREY, _GREY, _GREY, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                },
            }
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": _UINT32,
                "count": count,
                "type": "SCALAR",
                "min": [0],
                "max": [count - 1],
            },
            vec3(1, positions),
            vec3(2, per_vertex),
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": offsets[i], "byteLength": len(v), "target": target}
            for i, (v, target) in enumerate(
                zip(views, (_ELEMENT_ARRAY_BUFFER, _ARRAY_BUFFER, _ARRAY_BUFFER), strict=True)
            )
        ],
        "buffers": [{"byteLength": offsets[-1]}],
    }
    text = json.dumps(gltf, separators=(",", ":"), allow_nan=False).encode()
    text += b" " * (-len(text) % 4)  # chunks start 4-aligned; JSON pads with spaces
    binary = b"".join(views)  # 4-aligned already: 4-byte components
    total = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join(
        (
            struct.pack("<III", _GLTF, 2, total),
            struct.pack("<II", len(text), _JSON),
            text,
            struct.pack("<II", len(binary), _BIN),
            binary,
        )
    )
