"""Ctrl-C belongs to the driver. The terminal sends SIGINT to every process of the foreground
job, the local cluster's worker processes included; each would die printing a
KeyboardInterrupt traceback over the user's screen while the driver cancels the sweep and
closes them in order. So the workers ignore SIGINT: they inherit SIG_IGN from the driver while
the cluster starts them (Python keeps an inherited SIG_IGN for SIGINT), and this module, a
Dask preload, sets it again in any worker the cluster starts later (a nanny replacing a dead
worker).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

PRELOAD = __name__


def dask_setup(worker: Any) -> None:
    """Dask's preload hook, run in each worker process as it starts."""
    del worker
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextmanager
def sigint_ignored() -> Iterator[None]:
    """SIGINT ignored in this process (so in the processes it starts) for the block; a no-op
    outside the main thread, where Python cannot change signal handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
