"""Camera sources behind one small protocol: the simulated camera renders the scene at the
pose the vehicle reports; an OpenCV camera grabs a real frame (the pose is then only
recorded). ``--camera sim | opencv:N | URL`` picks one from :data:`SOURCES`.

A live camera (a device, a network stream) is read by `LatestFrame` on a thread of its own:
it buffers frames, so a frame read on demand can be seconds old, and a read that stalls
would hold up the MAVLink loop. A video file is read a frame per request, as a file has no
"now"."""

from __future__ import annotations

import os
import threading
import time
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
    captured_at_s: float | None
    """When the frame the last `capture` returned was taken (``time.monotonic``), or None:
    during that call."""

    def capture(self, pose: CameraPose) -> U8Array:
        """A (H, W, 3) uint8 RGB frame taken now (simulated ones at ``pose``)."""
        ...

    def close(self) -> None: ...


class SimCamera:
    """Renders ``scene`` at the reported pose (deterministic; optional seeded noise)."""

    def __init__(self, scene: Scene, intrinsics: Intrinsics, *, noise_seed: int | None) -> None:
        self.name = "sim"
        self.captured_at_s: float | None = None
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
        # FFmpeg's own log (a refused stream's "[tcp @ …] Connection … refused") too, unless
        # the user asks for it; read by OpenCV when its FFmpeg backend starts.
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
        import cv2  # noqa: PLC0415

        self.name = f"opencv:{source}"
        self.captured_at_s: float | None = None
        # OpenCV logs each backend it tried ([ WARN] lines) before our one-line error says
        # the same: silent while opening, as it was before.
        level = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
        try:
            self._cap: Any = cv2.VideoCapture(source)
            ok, frame = self._cap.read() if self._cap.isOpened() else (False, None)
        finally:
            cv2.utils.logging.setLogLevel(level)
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


FIRST_FRAME_S = 5.0
"""How long `LatestFrame` waits for a live camera's first frame."""
STALE_S = 2.0
"""A live camera whose newest frame is older than this has stopped giving frames."""


class LatestFrame:
    """Reads ``camera`` on a thread of its own, as fast as it gives frames, and hands out the
    newest one with the time it arrived (``captured_at_s``). `capture` raises CameraError
    when the camera failed, gave no frame in :data:`FIRST_FRAME_S`, or none for
    :data:`STALE_S`."""

    def __init__(self, camera: CameraSource, *, clock: Callable[[], float] = time.monotonic):
        self.name = camera.name
        self.intrinsics = camera.intrinsics
        self.captured_at_s: float | None = None
        self._camera = camera
        self._clock = clock
        self._changed = threading.Condition()
        self._newest: tuple[U8Array, float] | None = None
        self._error: CameraError | None = None
        self._stop = False
        self._thread = threading.Thread(target=self._read, name=f"camera {camera.name}")
        self._thread.daemon = True  # a read that never returns must not keep the process up
        self._thread.start()

    def _read(self) -> None:
        anywhere = CameraPose((0.0, 0.0, 0.0), 0.0, -90.0)  # a real camera ignores the pose
        while not self._stop:
            try:
                frame = self._camera.capture(anywhere)
            except CameraError as exc:
                error: CameraError | None = exc
            except Exception as exc:  # any failure of the camera's library ends the frames
                error = CameraError(f"camera {self.name}: {exc}")
            else:
                error = None
            with self._changed:
                if error is not None:
                    self._error = error
                else:
                    self._newest = (frame, self._clock())
                self._changed.notify_all()
            if error is not None:
                return

    def capture(self, pose: CameraPose) -> U8Array:
        del pose
        with self._changed:
            self._changed.wait_for(
                lambda: self._newest is not None or self._error is not None, FIRST_FRAME_S
            )
            if self._error is not None:
                raise self._error
            if self._newest is None:
                raise CameraError(f"camera {self.name}: no frame in {FIRST_FRAME_S:g} s")
            frame, at = self._newest
        if self._clock() - at > STALE_S:
            raise CameraError(f"camera {self.name}: no new frame for {STALE_S:g} s")
        self.captured_at_s = at
        return frame

    def close(self) -> None:
        self._stop = True
        self._thread.join(timeout=STALE_S)
        if not self._thread.is_alive():  # else it is stuck in a read: leave the camera to it
            self._camera.close()


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
    return LatestFrame(OpenCvCamera(source, hfov_deg=intrinsics.hfov_deg))


_FILE_SCHEMES = ("file",)


def _url(arg: str, _scene: Scene, intrinsics: Intrinsics, _seed: int | None) -> CameraSource:
    camera = OpenCvCamera(arg, hfov_deg=intrinsics.hfov_deg)
    live = arg.partition("://")[0].lower() not in _FILE_SCHEMES
    return LatestFrame(camera) if live else camera


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
