"""``uavtool sitl`` as a separate process on a loopback UDP port, as a user would run it."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


@contextmanager
def sitl_process(endpoint: str, *args: str) -> Iterator[None]:
    """``uavtool sitl ARGS --endpoint ENDPOINT`` in its own process, bound and serving once
    this yields; stopped on exit, and its output must hold no traceback."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "uavtool", "sitl", *args, "--endpoint", endpoint],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert proc.stdout is not None
        banner = proc.stdout.readline() + proc.stdout.readline()
        assert endpoint in banner, banner  # bound and serving
        yield
    finally:
        proc.terminate()
        out, _ = proc.communicate(timeout=10)
        assert "Traceback" not in out, out


@contextmanager
def sitl_udpin(*, speedup: float, scene: str = "paper") -> Iterator[int]:
    """A vehicle listening on ``udpin:127.0.0.1:PORT`` (yields the port), stopped on exit,
    with a mount (ArduCopter, and `uavtool sitl`, boot without one)."""
    port = free_udp_port()
    args = ("--speedup", str(speedup), "--scene", scene, "--param", "MNT1_TYPE=1")
    with sitl_process(f"udpin:127.0.0.1:{port}", *args):
        yield port
