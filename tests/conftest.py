"""Suite-wide settings.

- Workers (pytest-xdist, ``-n auto`` in ``pyproject.toml``): one more than this process may
  use cores. Many tests wait on real time (a ground station's heartbeat each second, a
  real-time link, a browser drawing, a recorder's ``--duration``) and leave their core idle
  meanwhile: with a worker per core the suite kept 1.3 of 2 cores busy and took 4 min 33 s,
  with one more 1.65 and 3 min 30 s. ``-n N`` sets it; ``-n 0`` runs in this process.
- What runs together (``--dist loadscope`` in ``pyproject.toml``): a module's tests on one
  worker, so its module-scoped fixtures (a recorded flight, a sweep) are made once, and the
  real autopilots' tests (``tests/integration``) all on one worker, one after the other: PX4
  takes fixed ports, and both keep time by the wall clock.
- In CI (``CI`` set, as GitHub Actions and ``.ci/run`` set it) the suite prints its 20
  slowest tests, so a test that grows slow shows where it is run.
"""

from __future__ import annotations

import os
from typing import Any

import pytest
from xdist.scheduler import LoadScopeScheduling

ONE_WORKER = ("tests/integration/",)
"""Folders whose tests run on one worker, one after the other."""


class _Scheduling(LoadScopeScheduling):
    def _split_scope(self, nodeid: str) -> str:
        for folder in ONE_WORKER:
            if nodeid.startswith(folder):
                return folder
        return super()._split_scope(nodeid)


def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    if config.getvalue("dist") != "loadscope":
        return None  # another --dist asked for: xdist's own
    return _Scheduling(config, log)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return cores + 1


def pytest_configure(config: pytest.Config) -> None:
    if os.environ.get("CI") and not config.option.durations:
        config.option.durations = 20
