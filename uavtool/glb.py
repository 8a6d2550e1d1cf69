"""A triangle mesh as binary glTF 2.0 (GLB): what recordings and ``uavtool vision model`` write
for a 3D model, and what Foxglove's, Lichtblick's and Rerun's 3D views load.

Written here in plain Python rather than by trimesh: one flat-shaded mesh needs a few dozen
lines of the format (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html), and
importing trimesh (~0.5 G instructions, ~0.15 s) or even numpy (~0.3 G) cost a recording's
writer process that much in every flight, beside the flight. A model has a few hundred faces
(~1.5 ms); plain Python takes ~6 us a face, numpy would take ~1 us.
"""

from __future__ import annotations

import json
import math
import struct
import sys
from array import array
from collections.abc import Iterable
from typing import Any

# glTF's constants: the chunk types, a primitive of triangles, component types
_GLTF, _JSON, _BIN = 0x46546C67, 0x4E4F534A, 0x004E4942
_TRIANGLES, _UINT32, _FLOAT32 = 4, 5125, 5126
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963  # what a buffer view holds: vertices, indices
_GREY = 190 / 255  # the model's matte light grey


def mesh_glb(vertices_m: Iterable[Iterable[float]], faces: Iterable[Iterable[int]]) -> bytes:
    """``vertices_m`` ``(n, 3)`` and ``faces`` ``(m, 3)`` (indices, counter-clockwise seen
    from outside; arrays or nested sequences) as GLB bytes, shaded as flat light-grey faces.

    Each face gets its own three vertices and its unit normal, and the mesh a matte material:
    viewers built on three.js (Foxglove's and Lichtblick's 3D panels) compute no normals for
    a glTF mesh that has none and draw it black. Faces without area are left out: they draw
    nothing, and glTF has no normal for them.

    Raises ValueError for a face index out of range, a vertex not finite, or no face with an
    area."""
    # numpy's arrays become lists first: iterating over them is ~5x slower
    vertices_m, faces = (getattr(x, "tolist", lambda x=x: x)() for x in (vertices_m, faces))
    points = [_point(v) for v in vertices_m]
    corners: list[tuple[float, ...]] = []  # each drawn face's three corners
    normals: list[tuple[float, float, float]] = []
    for face in faces:
        i, j, k = (int(n) for n in face)
        if min(i, j, k) < 0 or max(i, j, k) >= len(points):
            raise ValueError(f"a face index is outside the mesh's {len(points)} vertices")
        a, b, c = points[i], points[j], points[k]
        ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        vx, vy, vz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        if length > 0:  # a face without area draws nothing and has no normal
            corners += (a, b, c)
            normals.append((nx / length, ny / length, nz / length))
    if not normals:
        raise ValueError("a GLB mesh needs a face with an area; this one has none")
    count = 3 * len(normals)
    indices = array("I", range(count))  # 4 bytes on every platform CPython runs on
    positions = array("f", [x for p in corners for x in p])
    per_vertex = array("f", [x for n in normals for x in n * 3])
    views = [_little_endian(v) for v in (indices, positions, per_vertex)]  # each 4-aligned
    offsets = [0, len(views[0]), len(views[0]) + len(views[1]), sum(map(len, views))]

    def vec3(view: int, values: array[float]) -> dict[str, Any]:
        axes = [values[axis::3] for axis in range(3)]  # float32 values, as written
        return {
            "bufferView": view,
            "componentType": _FLOAT32,
            "count": count,
            "type": "VEC3",
            "min": [min(axis) for axis in axes],
            "max": [max(axis) for axis in axes],
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


def _point(vertex: Iterable[float]) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in vertex)
    if not math.isfinite(x + y + z):
        raise ValueError("a mesh's vertex is not a finite point")
    return x, y, z


def _little_endian(values: array[Any]) -> bytes:
    """glTF's binary data is little-endian."""
    if sys.byteorder == "little":
        return values.tobytes()
    swapped = array(values.typecode, values)
    swapped.byteswap()
    return swapped.tobytes()
