"""Lichtblick's own MCAP parsing code, built from a checkout of its repository and run in
node over a recording (`lichtblick_parse.ts`).

Lichtblick publishes neither its app nor its ``mcap-support`` package on npm, so the code
comes from a checkout named by ``$UAVTOOL_LICHTBLICK`` (a clone of
github.com/lichtblick-suite/lichtblick, or a bare mirror of it). Its
``packages/mcap-support/src`` is copied into a cache folder outside the repository
(``$UAVTOOL_NPM_CACHE``, default ``~/.cache/uavtool/npm``), its dependencies are installed
from npm at the versions its ``package.json`` pins (with its own protobufjs patch applied),
and the harness is bundled with esbuild.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any

from tests.npm_cache import installing, npm_cache

HARNESS = Path(__file__).with_name("lichtblick_parse.ts")
_SRC = "packages/mcap-support"


def checkout() -> Path | None:
    """The checkout ``$UAVTOOL_LICHTBLICK`` names, if it holds Lichtblick's mcap-support."""
    named = os.environ.get("UAVTOOL_LICHTBLICK")
    if not named:
        return None
    path = Path(named)
    return path if git(path, "cat-file", "-e", f"HEAD:{_SRC}/package.json") is not None else None


def cache_folder(repo: Path, kind: str) -> Path:
    """Where ``kind`` built from ``repo``'s HEAD is kept (``$UAVTOOL_NPM_CACHE``, default
    ``~/.cache/uavtool/npm``)."""
    head = (git(repo, "rev-parse", "--short", "HEAD") or b"").decode().strip()
    return npm_cache() / f"{kind}-{head}"


def build(repo: Path) -> Path:
    """The bundled harness for ``repo``'s HEAD (built on first use)."""
    folder = cache_folder(repo, "lichtblick")
    with installing(folder):
        return _build(repo, folder)


def _build(repo: Path, folder: Path) -> Path:
    bundle = folder / "lichtblick_parse.cjs"
    if bundle.is_file():
        return bundle
    folder.mkdir(parents=True, exist_ok=True)
    tar = git(repo, "archive", "HEAD", f"{_SRC}/src")
    subprocess.run(["tar", "-x", "-C", str(folder)], input=tar, check=True)
    shutil.copytree(folder / _SRC / "src", folder / "src", dirs_exist_ok=True)
    manifest = json.loads(git(repo, "show", f"HEAD:{_SRC}/package.json") or b"{}")
    specs = []
    for name, pinned in manifest["dependencies"].items():
        # "patch:protobufjs@7.2.5#../../patches/protobufjs.patch": the version, patched below
        patched = pinned.startswith("patch:")
        specs.append(f"{name}@{pinned.split('@', 1)[1].split('#', 1)[0] if patched else pinned}")
    (folder / "package.json").write_text('{"name": "lichtblick-check", "private": true}\n')
    subprocess.run(
        ["npm", "install", "--no-audit", "--no-fund", "--prefix", str(folder), *specs,
         "esbuild@0.24"],
        check=True, capture_output=True, timeout=600,
    )  # fmt: skip
    patch = git(repo, "show", "HEAD:patches/protobufjs.patch")
    if patch:
        subprocess.run(
            ["patch", "-p1", "-d", str(folder / "node_modules" / "protobufjs")],
            input=patch, check=True, capture_output=True,
        )  # fmt: skip
    shutil.copy(HARNESS, folder / HARNESS.name)
    subprocess.run(
        [str(folder / "node_modules" / ".bin" / "esbuild"), HARNESS.name, "--bundle",
         "--platform=node", "--format=cjs", "--loader:.wasm=file", f"--outfile={bundle.name}"],
        cwd=folder, check=True, capture_output=True, timeout=300,
    )  # fmt: skip
    for wasm in (folder / "node_modules" / "@lichtblick").rglob("*.wasm"):
        shutil.copy(wasm, folder / wasm.name)  # the decompressors load theirs beside the bundle
    return bundle


def parse(bundle: Path, recording: Path) -> dict[str, Any]:
    """What Lichtblick's parser makes of ``recording``: channel and message counts, the
    problems per topic, and the first ``/mavlink/in/ATTITUDE`` roll."""
    done = subprocess.run(
        ["node", str(bundle), str(recording)],
        check=False, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    result: dict[str, Any] = json.loads(done.stdout)
    return result


def git(repo: Path, *args: str) -> bytes | None:
    """``git -C repo args``'s output, or None if it fails."""
    done = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, check=False)
    return done.stdout if done.returncode == 0 else None
