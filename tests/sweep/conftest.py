"""A real 2-worker Dask LocalCluster (processes), shared by the sweep and batch-replay tests."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest


@pytest.fixture(scope="package")
def cluster() -> Iterator[object]:
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=logging.ERROR,
    ) as local:
        yield local


@pytest.fixture(scope="package")
def scheduler(cluster: object) -> str:
    return str(cluster.scheduler_address)  # type: ignore[attr-defined]
