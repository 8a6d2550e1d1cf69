"""MAVProxy in an environment of its own, as users install an application (pipx-style).

MAVProxy is not in uavtool's test extra: on Linux it requires ``opencv-python``, whose ``cv2``
would overwrite ``opencv-python-headless``'s (ours) in the same environment, so the suite would
test another OpenCV than users get (one that needs libGL and X libraries). The first test that
needs MAVProxy builds a virtualenv for it in a cache folder, with the same Python, and later
runs reuse it. ``UAVTOOL_MAVPROXY`` names a ready ``mavproxy.py`` instead.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

VERSION = "1.8.75"
"""The release the MAVProxy test was written against (its expected lines are MAVProxy's)."""


def _cache_root() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "uavtool-tests"


def _unavailable(reason: str) -> None:
    if os.environ.get("CI") == "true":  # CI reaches PyPI: there a missing MAVProxy is a failure
        pytest.fail(f"MAVProxy {VERSION}: {reason}")
    pytest.skip(f"MAVProxy {VERSION} could not be installed in its own environment: {reason}")


def mavproxy_command() -> list[str]:
    """The command that starts MAVProxy (arguments follow), installing it on first use."""
    named = os.environ.get("UAVTOOL_MAVPROXY")
    if named:
        return [named]
    tag = f"mavproxy-{VERSION}-py{sys.version_info.major}.{sys.version_info.minor}"
    home = _cache_root() / tag
    python = home / "bin" / "python"
    if not (home / "ready").exists():
        partial = home.with_name(f"{tag}.{os.getpid()}.partial")
        shutil.rmtree(partial, ignore_errors=True)
        venv.create(partial, with_pip=True)
        done = subprocess.run(
            [str(partial / "bin" / "python"), "-m", "pip", "install", "-q", f"MAVProxy=={VERSION}"],
            capture_output=True,
            text=True,
            timeout=900,
            check=False,
        )
        if done.returncode != 0:
            shutil.rmtree(partial, ignore_errors=True)
            _unavailable(f"pip install failed: {done.stderr.strip().splitlines()[-1:]}")
        (partial / "ready").write_text(VERSION + "\n")
        shutil.rmtree(home, ignore_errors=True)
        partial.rename(home)
    return [str(python), "-m", "MAVProxy.mavproxy"]
