"""`uavtool.glb`: the model's GLB, read back by trimesh's glTF loader and checked by the
Khronos Group's own glTF validator (npm's ``gltf-validator``, when node and npm are here)."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh

from tests.npm_cache import npm_cache, npm_installed
from uavtool.glb import mesh_glb

VALIDATOR = "gltf-validator@2.0.0-dev.3.10"
_RUN_VALIDATOR = """
const fs = require("fs");
const validator = require(process.argv[1]);
const reports = [];
(async () => {
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    reports.push(report.issues);
  }
  console.log(JSON.stringify(reports));
})().catch((err) => { console.error(String(err)); process.exit(1); });
"""

_TETRA = (
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
)


def _chunks(glb: bytes) -> tuple[dict[str, Any], bytes]:
    magic, version, total = struct.unpack_from("<III", glb)
    assert (magic, version, total) == (0x46546C67, 2, len(glb))
    text_len, kind = struct.unpack_from("<II", glb, 12)
    assert kind == 0x4E4F534A and text_len % 4 == 0
    bin_len, kind = struct.unpack_from("<II", glb, 20 + text_len)
    assert kind == 0x004E4942 and bin_len % 4 == 0 and 28 + text_len + bin_len == total
    gltf: dict[str, Any] = json.loads(glb[20 : 20 + text_len])
    return gltf, glb[28 + text_len :]


def _random_meshes(seed: int, count: int) -> list[tuple[Any, Any]]:
    rng = np.random.default_rng(seed)
    meshes = []
    for _ in range(count):
        vertices = rng.normal(size=(int(rng.integers(3, 40)), 3)) * rng.uniform(0.01, 500)
        faces = rng.integers(0, len(vertices), size=(int(rng.integers(1, 60)), 3))
        faces[0] = [0, 1, 2]  # at least one face with an area
        meshes.append((vertices, faces))
    return meshes


@pytest.mark.parametrize("mesh", [_TETRA, *_random_meshes(7, 12)])
def test_trimesh_reads_back_every_face_with_its_normal_and_the_matte_grey(mesh: Any) -> None:
    vertices, faces = np.asarray(mesh[0], float), np.asarray(mesh[1])
    loaded = trimesh.load(
        trimesh.util.wrap_as_stream(mesh_glb(vertices, faces)),
        file_type="glb",
        force="mesh",
        process=False,
    )
    triangles = vertices[faces]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    kept = np.linalg.norm(cross, axis=1) > 0  # faces without area are left out
    scale = np.abs(vertices).max()
    assert np.allclose(loaded.triangles, triangles[kept], rtol=0, atol=1e-6 * scale)
    unit = cross[kept] / np.linalg.norm(cross[kept], axis=1, keepdims=True)
    assert np.allclose(loaded.vertex_normals.reshape(-1, 3, 3), unit[:, None, :], atol=1e-6)
    material = loaded.visual.material
    assert np.allclose(material.baseColorFactor, [190, 190, 190, 255], atol=1)
    assert (material.metallicFactor, material.roughnessFactor) == (0.0, 1.0)


def test_the_accessors_bounds_are_the_datas_and_the_layout_glbs() -> None:
    gltf, data = _chunks(mesh_glb(*_TETRA))
    assert gltf["asset"] == {"version": "2.0", "generator": "uavtool"}
    views = gltf["bufferViews"]
    assert gltf["buffers"] == [{"byteLength": len(data)}]
    for accessor in gltf["accessors"]:
        view = views[accessor["bufferView"]]
        dtype = {5125: "<u4", 5126: "<f4"}[accessor["componentType"]]
        width = {"SCALAR": 1, "VEC3": 3}[accessor["type"]]
        start = view["byteOffset"]
        values = np.frombuffer(data[start : start + view["byteLength"]], dtype).reshape(-1, width)
        assert len(values) == accessor["count"] == 12
        assert values.min(axis=0).tolist() == accessor["min"]
        assert values.max(axis=0).tolist() == accessor["max"]


@pytest.mark.parametrize(
    ("vertices", "faces", "problem"),
    [
        (_TETRA[0], [[0, 1, 4]], "outside the mesh's 4 vertices"),
        (_TETRA[0], [[0, -1, 2]], "outside the mesh's 4 vertices"),
        (_TETRA[0], np.zeros((0, 3), int), "needs a face with an area"),
        (_TETRA[0], [[0, 0, 1], [2, 2, 2]], "needs a face with an area"),
        ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, np.nan, 0.0]], [[0, 1, 2]], "not a finite"),
    ],
)
def test_a_mesh_glb_cannot_hold_says_why(vertices: Any, faces: Any, problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        mesh_glb(vertices, faces)


def _validator() -> Path | None:
    """The Khronos glTF validator's package folder (installed from npm on first use, into
    ``$UAVTOOL_NPM_CACHE``, default ``~/.cache/uavtool/npm``); None without node or npm."""
    if shutil.which("node") is None or shutil.which("npm") is None:
        return None
    folder = npm_cache() / VALIDATOR.replace("@", "-")
    package = folder / "node_modules" / "gltf-validator"
    npm_installed(folder, VALIDATOR, package / "package.json")
    return package


def test_the_khronos_validator_finds_nothing_to_say(tmp_path: Path) -> None:
    """Not an error, a warning, an info nor a hint, for the tetrahedron, random meshes (with
    faces without area among them) and a mesh of a million-metre coordinates."""
    package = _validator()
    if package is None:
        pytest.skip("node and npm are needed to run the Khronos glTF validator")
    far = (np.asarray(_TETRA[0]) * 50 + 1e6, _TETRA[1])
    files = []
    for i, (vertices, faces) in enumerate([_TETRA, far, *_random_meshes(11, 6)]):
        files.append(tmp_path / f"{i}.glb")
        files[-1].write_bytes(mesh_glb(vertices, faces))
    done = subprocess.run(
        ["node", "-e", _RUN_VALIDATOR, str(package), *map(str, files)],
        check=False, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    for file, issues in zip(files, json.loads(done.stdout), strict=True):
        assert issues["messages"] == [], (file.name, issues["messages"])
