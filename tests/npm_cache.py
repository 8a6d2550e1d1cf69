"""Where tests keep what they install from npm (``$UAVTOOL_NPM_CACHE``, default
``~/.cache/uavtool/npm``), and a lock per installed folder: the suite's parallel workers
(pytest-xdist) install each package once, one after the other, and never read a half-made
folder."""

from __future__ import annotations

import fcntl
import os
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def npm_cache() -> Path:
    default = Path.home() / ".cache" / "uavtool" / "npm"
    return Path(os.environ.get("UAVTOOL_NPM_CACHE", default))


@contextmanager
def installing(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s lock (a file beside it): check whether it is made, and make it,
    inside."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    with (folder.parent / f"{folder.name}.lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def npm_installed(folder: Path, spec: str, marker: Path, *, timeout_s: float = 300.0) -> None:
    """Install ``spec`` (``name@version``) from npm into ``folder`` unless ``marker`` (a file
    the package holds) is there already; under ``folder``'s lock."""
    with installing(folder):
        if marker.is_file():
            return
        folder.mkdir(parents=True, exist_ok=True)
        subprocess.run(
            ["npm", "install", "--no-save", "--no-audit", "--no-fund", "--ignore-scripts",
             "--prefix", str(folder), spec],
            check=True, capture_output=True, timeout=timeout_s,
        )  # fmt: skip
