"""The environment the suite runs in is the one users get from ``pip install uavtool``."""

from __future__ import annotations

from importlib import metadata


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
