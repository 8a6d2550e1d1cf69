"""Foxglove Studio's own MCAP data source, run in node over a recording (`foxglove_source.cjs`).

Lichtblick's app is not published on npm (`@lichtblick/suite` holds only the extension API
types), and neither is Foxglove's app shell; `@foxglove/studio-base` 1.48.0, the last
open-source Studio core on npm, ships the built bundle with the MCAP source, its channel
parser (`parseChannel`, `parseJsonSchema`, Protobuf descriptors) and its deserializers, the
code Lichtblick forked. It is installed once into a cache folder outside the repository
(``$UAVTOOL_NPM_CACHE``, default ``~/.cache/uavtool/npm``).
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

from tests.npm_cache import npm_cache, npm_installed

PACKAGE = "@foxglove/studio-base"
VERSION = "1.48.0"
HARNESS = Path(__file__).with_name("foxglove_source.cjs")


def cache_dir() -> Path:
    return npm_cache() / f"studio-base-{VERSION}"


def assets() -> Path | None:
    """The installed bundle's assets folder (installing it on first use); None if npm or
    node is missing."""
    if shutil.which("node") is None or shutil.which("npm") is None:
        return None
    folder = cache_dir()
    found = folder / "node_modules" / PACKAGE / "assets"
    npm_installed(folder, f"{PACKAGE}@{VERSION}", found / "index.js", timeout_s=600)
    return found


def open_in_studio(bundle: Path, recording: Path) -> dict[str, Any]:
    """What Studio's data source makes of ``recording``: ``topics``, ``problems``,
    ``perTopic`` (decoded count and first message) and ``datatypes``."""
    done = subprocess.run(
        ["node", str(HARNESS), str(bundle), str(recording)],
        check=False, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    result: dict[str, Any] = json.loads(done.stdout)
    return result
