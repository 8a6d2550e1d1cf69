"""Camera sources behind one small protocol: the simulated camera renders the scene at the
pose the vehicle reports; an OpenCV camera grabs a real frame (the pose is then only
recorded). ``--camera sim | opencv:N | URL`` picks one from :data:`SOURCES`."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.errors import InputError
from uavtool.world import Scene, render

U8Array = npt.NDArray[np.uint8]


class CameraError(InputError):
    """The camera cannot be opened or gives no frame."""


class CameraSource(Protocol):
    """Something that takes photos. ``intrinsics`` describe its frames."""

    name: str
    intrinsics: Intrinsics

    def capture(self, pose: CameraPose) -> U8Array:
        """A (H, W, 3) uint8 RGB frame taken now (simulated ones at ``pose``)."""
        ...

    def close(self) -> None: ...


class SimCamera:
    """Renders ``scene`` at the reported pose (deterministic; optional seeded noise)."""

    def __init__(self, scene: Scene, intrinsics: Intrinsics, *, noise_seed: int | None) -> None:
        self.name = "sim"
        self.scene = scene
        self.intrinsics = intrinsics
        self.noise_seed = noise_seed
        self._count = 0

    def capture(self, pose: CameraPose) -> U8Array:
        self._count += 1
        seed = None if self.noise_seed is None else self.noise_seed + self._count
        return render(self.scene, pose, self.intrinsics, noise_seed=seed)

    def close(self) -> None:
        pass


class OpenCvCamera:
    """A camera OpenCV can open: a device index or a stream URL/file. Its field of view is
    not known to OpenCV: ``hfov_deg`` says it."""

    def __init__(self, source: int | str, *, hfov_deg: float) -> None:
        import cv2  # noqa: PLC0415

        self.name = f"opencv:{source}"
        self._cap: Any = cv2.VideoCapture(source)
        ok, frame = self._cap.read() if self._cap.isOpened() else (False, None)
        if not ok or frame is None:
            self._cap.release()
            raise CameraError(f"camera {self.name}: cannot open it or read a frame")
        h, w = frame.shape[:2]
        self.intrinsics = Intrinsics.from_hfov(width_px=w, height_px=h, hfov_deg=hfov_deg)

    def capture(self, pose: CameraPose) -> U8Array:
        import cv2  # noqa: PLC0415

        del pose  # a real camera is wherever the vehicle is
        ok, frame = self._cap.read()
        if not ok:
            raise CameraError(f"camera {self.name}: no frame")
        return np.ascontiguousarray(cv2.cvtColor(frame, cv2.COLOR_BGR2RGB))

    def close(self) -> None:
        self._cap.release()


Opener = Callable[[str, Scene, Intrinsics, int | None], CameraSource]


def _sim(_arg: str, scene: Scene, intrinsics: Intrinsics, seed: int | None) -> CameraSource:
    return SimCamera(scene, intrinsics, noise_seed=seed)


def _opencv(arg: str, _scene: Scene, intrinsics: Intrinsics, _seed: int | None) -> CameraSource:
    try:
        source: int | str = int(arg)
    except ValueError:
        raise CameraError(
            f"--camera opencv:{arg}: expected a device number, e.g. opencv:0"
        ) from None
    return OpenCvCamera(source, hfov_deg=intrinsics.hfov_deg)


def _url(arg: str, _scene: Scene, intrinsics: Intrinsics, _seed: int | None) -> CameraSource:
    return OpenCvCamera(arg, hfov_deg=intrinsics.hfov_deg)


SOURCES: dict[str, Opener] = {"sim": _sim, "opencv": _opencv}


def open_camera(
    spec: str, *, scene: Scene, intrinsics: Intrinsics, noise_seed: int | None
) -> CameraSource:
    """``sim``, ``opencv:N`` or a URL (``rtsp://…``, ``http://…``, a video file)."""
    kind, _, arg = spec.partition(":")
    if "://" in spec:
        return _url(spec, scene, intrinsics, noise_seed)
    opener = SOURCES.get(kind)
    if opener is None:
        raise CameraError(f"--camera {spec!r}: expected sim, opencv:N or a stream URL")
    return opener(arg, scene, intrinsics, noise_seed)
