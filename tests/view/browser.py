"""A headless Chromium driven over the DevTools protocol on a pipe (no extra packages).

Chromium reads protocol commands from fd 3 and writes replies and events to fd 4 when
started with ``--remote-debugging-pipe``; messages are JSON separated by NUL bytes.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    # WebGL on the CPU: recent Chromium only falls back to SwiftShader when allowed to.
    "--enable-unsafe-swiftshader",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-extensions",
    "--mute-audio",
)


def find_chromium() -> str | None:
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def install_chromium() -> str | None:
    """Install Debian's chromium if missing (root with apt only); its path, or None."""
    found = find_chromium()
    if found or shutil.which("apt-get") is None or os.geteuid() != 0:
        return found
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    for cmd in (["apt-get", "update", "-qq"], ["apt-get", "install", "-y", "-qq", "chromium"]):
        if subprocess.run(cmd, env=env, capture_output=True, check=False, timeout=600).returncode:
            return None
    return find_chromium()


_COLLECT_ERRORS = """
window.__uavtoolErrors = [];
window.addEventListener("error", (e) => window.__uavtoolErrors.push("uncaught: " + e.message));
window.addEventListener("unhandledrejection",
  (e) => window.__uavtoolErrors.push("unhandled rejection: " + String(e.reason)));
const __uavtoolConsoleError = console.error.bind(console);
console.error = (...args) => {
  window.__uavtoolErrors.push("console.error: " + args.map(String).join(" "));
  __uavtoolConsoleError(...args);
};
"""


class Browser:
    """One headless Chromium; `open` a page, collect its errors, take screenshots."""

    def __init__(
        self, executable: str, profile: Path, *, size: tuple[int, int] = (1600, 1000)
    ) -> None:
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()
        args = [executable, *FLAGS, f"--window-size={size[0]},{size[1]}"]
        args += [f"--user-data-dir={profile}", "--remote-debugging-pipe", "about:blank"]
        # fds 3 and 4 of the child must be the two pipe ends.
        script = f'exec "$@" 3<&{to_child_r} 4>&{from_child_w}'
        self.proc = subprocess.Popen(
            ["bash", "-c", script, "chromium", *args],
            pass_fds=(to_child_r, from_child_w),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_child_r)
        os.close(from_child_w)
        self._next_id = 0
        self._replies: dict[int, dict[str, Any]] = {}
        self._cond = threading.Condition()
        self.session: str | None = None
        self.events: list[dict[str, Any]] = []  # only Page and Network events are enabled
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        buf = b""
        while True:
            try:
                data = os.read(self._from_child, 1 << 16)
            except OSError:
                data = b""
            if not data:
                with self._cond:
                    self._cond.notify_all()
                return
            buf += data
            *messages, buf = buf.split(b"\0")
            for raw in messages:
                msg = json.loads(raw)
                with self._cond:
                    if "id" in msg:
                        self._replies[msg["id"]] = msg
                        self._cond.notify_all()
                    else:
                        self.events.append(msg)

    def call(
        self,
        method: str,
        params: dict[str, Any] | None = None,
        *,
        timeout_s: float = 30.0,
        session: bool = True,
    ) -> dict[str, Any]:
        self._next_id += 1
        msg: dict[str, Any] = {"id": self._next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        os.write(self._to_child, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while self._next_id not in self._replies:
                left = deadline - time.monotonic()
                if left <= 0 or self.proc.poll() is not None:
                    raise TimeoutError(f"chromium: no reply to {method}")
                self._cond.wait(left)
            reply = self._replies.pop(self._next_id)
        if "error" in reply:
            raise RuntimeError(f"chromium: {method}: {reply['error']}")
        return dict(reply.get("result", {}))

    def open(self, url: str) -> None:
        """Open ``url`` in a new tab that records its errors (see `js_errors`).

        The page's console is not streamed to us: the Rerun viewer logs thousands of debug
        lines while loading and forwarding them slows the software renderer to a crawl."""
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)
        attached = self.call(
            "Target.attachToTarget",
            {"targetId": target["targetId"], "flatten": True},
            session=False,
        )
        self.session = attached["sessionId"]
        self.call("Page.enable")
        self.call("Network.enable")
        self.call("Page.addScriptToEvaluateOnNewDocument", {"source": _COLLECT_ERRORS})
        self.call("Page.navigate", {"url": url})

    def js_errors(self) -> list[str]:
        """Uncaught exceptions, unhandled rejections and console.error calls so far."""
        return list(self.evaluate("window.__uavtoolErrors || []") or [])

    def failed_requests(self) -> list[str]:
        """URLs of the page's requests that failed (DNS, refused, aborted …)."""
        with self._cond:
            events = list(self.events)
        urls = {
            e["params"]["requestId"]: e["params"]["request"]["url"]
            for e in events
            if e.get("method") == "Network.requestWillBeSent"
        }
        return [
            urls.get(e["params"]["requestId"], "?")
            for e in events
            if e.get("method") == "Network.loadingFailed"
        ]

    def evaluate(self, expression: str) -> Any:
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True})
        return result.get("result", {}).get("value")

    def screenshot(self, path: Path) -> bytes:
        data = base64.b64decode(self.call("Page.captureScreenshot", {"format": "png"})["data"])
        path.write_bytes(data)
        return data

    def close(self) -> None:
        with contextlib.suppress(TimeoutError, RuntimeError, OSError):
            self.call("Browser.close", session=False, timeout_s=5.0)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_child, self._from_child):
            with contextlib.suppress(OSError):
                os.close(fd)
