"""Where tasks run: a Dask ``LocalCluster`` of worker processes sized to the machine (one
single-threaded worker per core: flights are CPU-bound Python), or any running Dask
scheduler given by address (``dask scheduler`` plus ``dask worker`` elsewhere, or any Dask
deployment). Nothing else about a sweep changes with the cluster. The local cluster's workers
ignore Ctrl-C (:mod:`~uavtool.sweep.interrupt`): the driver stops the sweep and closes them."""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from uavtool.errors import InputError
from uavtool.sweep.interrupt import PRELOAD, sigint_ignored

if TYPE_CHECKING:
    from distributed import Client


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@contextmanager
def open_client(scheduler: str | None = None, *, workers: int | None = None) -> Iterator[Client]:
    """A connected client; a LocalCluster (closed on exit) unless ``scheduler`` is given.
    Raises InputError when the scheduler cannot be reached."""
    from distributed import Client, LocalCluster  # noqa: PLC0415

    _quiet_dask()
    if scheduler is not None:
        if workers is not None:
            raise InputError(
                "--workers sizes the local cluster; with --scheduler, start workers there"
            )
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
        with client:
            yield client
        return
    n = workers if workers is not None else default_workers()
    if n < 1:
        raise InputError(f"--workers must be ≥ 1, got {n}")
    # The workers must not hear the terminal's Ctrl-C: see uavtool.sweep.interrupt.
    with sigint_ignored():
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # no fixed port: several clusters may run at once
            silence_logs=logging.ERROR,
            preload=[PRELOAD],
        )
    with cluster, Client(cluster) as client:
        yield client


def _quiet_dask() -> None:
    """distributed sets its loggers to INFO when imported: its start-up and shutdown chatter
    would bury the progress line. Keep it only when the user asked for -v."""
    root = logging.getLogger().getEffectiveLevel()
    logging.getLogger("distributed").setLevel(root if root <= logging.INFO else logging.ERROR)
