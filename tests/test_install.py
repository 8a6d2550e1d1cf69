"""The environment the suite runs in is the one users get from ``pip install uavtool``."""

from __future__ import annotations

from importlib import metadata

import uavtool


def _owners(path: str) -> list[str]:
    return sorted(
        str(dist.metadata["Name"])
        for dist in metadata.distributions()
        if any(str(f) == path for f in dist.files or ())
    )


def test_one_opencv_owns_cv2() -> None:
    # Two OpenCV wheels in one environment overwrite each other's cv2 (whichever installed
    # last wins, and uninstalling either breaks the other): the test extra must not pull a
    # second one (MAVProxy requires opencv-python; it gets an environment of its own).
    owners = _owners("cv2/__init__.py")
    assert len(owners) == 1, f"cv2 is installed by {owners}"
    assert owners[0].endswith("-headless"), f"cv2 comes from {owners[0]}, not a headless build"


def test_the_version_uavtool_reports_is_the_installed_one() -> None:
    # uavtool.__version__ is a literal that pyproject.toml reads at build time (importing
    # importlib.metadata at start-up costs ~25 ms): an install made before a version change
    # would disagree.
    assert uavtool.__version__ == metadata.version("uavtool")
