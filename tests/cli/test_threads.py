"""The command line keeps numpy's OpenBLAS on one thread: its workers only spin-wait after
the flight's small matrix products, on the core a writer process or a sweep's other workers
use. A user's own setting wins."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

# the entry point's own preparation, then a product large enough for OpenBLAS to share out
_SCRIPT = (
    "import os, sys\n"
    "from uavtool import cli\n"
    "cli._one_blas_thread()\n"
    "import numpy as np\n"
    "a = np.ones((400, 400))\n"
    "a @ a\n"
    "print(len(os.listdir('/proc/self/task')), os.environ['OPENBLAS_NUM_THREADS'])\n"
)


def _threads(env_value: str | None) -> tuple[int, str]:
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if env_value is not None:
        env["OPENBLAS_NUM_THREADS"] = env_value
    run = subprocess.run(
        [sys.executable, "-c", _SCRIPT], capture_output=True, text=True, env=env, check=True
    )
    count, setting = run.stdout.split()
    return int(count), setting


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux's /proc")
def test_numpy_runs_its_products_on_one_thread_unless_the_user_says_otherwise() -> None:
    assert _threads(None) == (1, "1")
    if (os.cpu_count() or 1) > 1:
        count, setting = _threads("2")
        assert setting == "2" and count >= 2  # the user's choice, and OpenBLAS's workers
