"""Ctrl-C belongs to the driver. The terminal sends SIGINT to every process of the foreground
job, the local cluster's worker processes included; each would die printing a
KeyboardInterrupt traceback over the user's screen while the driver cancels the sweep and
closes them in order. So the workers do not die of it: they inherit SIG_IGN from the driver
while the cluster starts them (Python keeps an inherited SIG_IGN for SIGINT), and this module,
a Dask preload run in every worker the cluster starts (a nanny's replacement for a dead worker
too), gives SIGINT a handler that only quiets the worker's logs.

Stopping a cluster mid-task is noisy: the scheduler cannot gather a result it was asked for
and the driver has just cancelled, workers find their connections (TLS streams) closed under
them, and Dask, Tornado and asyncio log each at ERROR. After a Ctrl-C that is expected, so the
driver quiets those loggers (:class:`QuietLogs`) from the moment the interrupt arrives until
the cluster is closed, and each worker quiets its own when it hears the same SIGINT.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

PRELOAD = __name__

_NOISY = ("distributed", "tornado", "asyncio")
"""The loggers (with their children) that report a cluster's shutdown as errors."""


class QuietLogs:
    """Dask's, Tornado's and asyncio's loggers raised to CRITICAL, and put back."""

    def __init__(self) -> None:
        self._levels: dict[str, int] = {}

    def quiet(self) -> None:
        """Raise them (those that exist now too: distributed names a logger per module, and
        its configuration sets some children's levels, e.g. ``tornado.application``)."""
        known = list(logging.root.manager.loggerDict)
        for name in (*_NOISY, *(n for n in known if n.split(".", 1)[0] in _NOISY)):
            logger = logging.getLogger(name)
            self._levels.setdefault(name, logger.level)
            logger.setLevel(logging.CRITICAL)

    def restore(self) -> None:
        for name, level in self._levels.items():
            logging.getLogger(name).setLevel(level)
        self._levels.clear()


def dask_setup(worker: Any) -> None:
    """Dask's preload hook, run in each worker process as it starts: Ctrl-C quiets the worker's
    logs (the driver is about to close it) and does nothing else."""
    del worker
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _quiet_worker)


def _quiet_worker(_signum: int, _frame: object) -> None:
    QuietLogs().quiet()


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


@contextmanager
def quiet_on_sigint(logs: QuietLogs) -> Iterator[None]:
    """For the block, Ctrl-C quiets ``logs`` before it raises KeyboardInterrupt: the
    scheduler runs in this process's other threads and may log the interrupted work's errors
    before the driver's ``except`` is reached. A no-op outside the main thread, or where
    SIGINT has a handler of its own (not Python's default)."""
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield
        return

    def interrupted(signum: int, frame: Any) -> None:
        logs.quiet()
        signal.default_int_handler(signum, frame)

    signal.signal(signal.SIGINT, interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
