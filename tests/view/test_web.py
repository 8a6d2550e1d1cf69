"""`uavtool view REC --web` in a real headless browser (Debian's chromium): the viewer
loads without JavaScript errors and shows the 3D route and the camera frame with its vectors.

The screenshot is kept in the test's tmp dir (and copied to /tmp/view_screenshot.png).
Software rendering is slow: the viewer needs ~10 s on two cores to show everything at 960 x 600
(~25 s at 1280 x 800: every pixel drawn costs the suite CPU).
"""

from __future__ import annotations

import select
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
import pytest

from tests.view.browser import Browser, install_chromium

pytestmark = pytest.mark.slow

ROUTE_BGR = (0, 220, 255)  # the route's yellow (entities._ROUTE_RGB)
VECTOR_BGR = (255, 255, 0)  # the vectors' cyan (entities._VECTOR_RGB)
SIZE = (960, 600)


@pytest.fixture(scope="module")
def chromium() -> str:
    path = install_chromium()
    if path is None:
        pytest.skip("no chromium, and it cannot be installed here (needs root and apt-get)")
    return path


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


@pytest.fixture
def served(recording: Path) -> Iterator[str]:
    """``uavtool view REC --web`` running; yields the URL it printed."""
    web, grpc = _free_port(), _free_port()
    cmd = [sys.executable, "-m", "uavtool", "view", str(recording), "--web"]
    cmd += ["--web-port", str(web), "--grpc-port", str(grpc)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        url = _read_url(proc, timeout_s=60.0)
        assert url.startswith(f"http://127.0.0.1:{web}/?url=rerun%2Bhttp")
        with urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=10) as page:
            assert page.status == 200
            assert b"Rerun" in page.read()
        # Both servers on 127.0.0.1 only (issue 30: they listened on every interface)
        listening = _listening_addresses({web, grpc})
        assert listening == {("127.0.0.1", web), ("127.0.0.1", grpc)}, listening
        yield url
    finally:
        proc.terminate()
        try:
            proc.communicate(timeout=10)  # also closes the pipes
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()


def _listening_addresses(ports: set[int]) -> set[tuple[str, int]]:
    """(address, port) of every listening TCP socket on ``ports``, from /proc/net/tcp{,6}."""
    found = set()
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        with Path(name).open(encoding="ascii") as table:
            for line in list(table)[1:]:
                local, state = line.split()[1], line.split()[3]
                address, port = local.split(":")
                if state == "0A" and int(port, 16) in ports:  # LISTEN
                    ip = (
                        ".".join(str(b) for b in reversed(bytes.fromhex(address)))
                        if len(address) == 8
                        else address
                    )
                    found.add((ip, int(port, 16)))
    return found


def _read_url(proc: subprocess.Popen[str], *, timeout_s: float) -> str:
    assert proc.stdout is not None
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        ready, _, _ = select.select([proc.stdout], [], [], 0.5)
        if ready:
            line = proc.stdout.readline()
            if line.startswith("web viewer: "):
                return line.removeprefix("web viewer: ").strip()
            if not line and proc.poll() is not None:
                break
    err = proc.stderr.read() if proc.poll() is not None and proc.stderr else ""
    pytest.fail(f"uavtool view --web printed no URL: {err}")


def _count(image: npt.NDArray[np.uint8], bgr: tuple[int, int, int], tol: int = 40) -> int:
    diff = np.abs(image.astype(np.int16) - np.array(bgr, dtype=np.int16)).max(axis=2)
    return int((diff <= tol).sum())


def _looks_loaded(png: bytes) -> bool:
    image = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    h, w = image.shape[:2]
    world, camera = image[: h // 2, : w * 3 // 5], image[h // 2 :, : w * 3 // 5]
    return _count(world, ROUTE_BGR) > 300 and _count(camera, VECTOR_BGR) > 150


def test_web_viewer_shows_route_and_camera_without_js_errors(
    served: str, chromium: str, tmp_path: Path
) -> None:
    shot = tmp_path / "view_screenshot.png"
    browser = Browser(chromium, tmp_path / "profile", size=SIZE)
    try:
        browser.open(served)
        previous, loaded = b"", False
        deadline = time.monotonic() + 150.0
        while time.monotonic() < deadline and not loaded:
            time.sleep(2.0)
            png = browser.screenshot(shot)
            # loaded: everything drawn, and nothing changed since the last look
            loaded = png == previous and _looks_loaded(png)
            previous = png
        errors = browser.js_errors()
        failed = browser.failed_requests()
    finally:
        browser.close()
    shutil.copy(shot, "/tmp/view_screenshot.png")
    assert loaded, f"the viewer did not show the route and the camera frame: see {shot}"
    local = [u for u in failed if u.startswith(("http://localhost", "http://127.0.0.1"))]
    assert not local, f"requests to our own servers failed: {local}"
    # The viewer phones home (fonts, version check, analytics); with no internet each such
    # fetch fails and is logged once as "Failed to fetch". Anything else is a real error.
    external = len(failed) - len(local)
    fetch_errors = [e for e in errors if e == "console.error: TypeError: Failed to fetch"]
    other = [e for e in errors if e not in fetch_errors]
    assert not other, other
    assert len(fetch_errors) <= external
