"""Suite-wide settings.

- Workers (pytest-xdist, ``-n auto`` in ``pyproject.toml``): one more than this process may
  use cores. Many tests wait on real time (a ground station's heartbeat each second, a
  real-time link, a browser drawing, a recorder's ``--duration``) and leave their core idle
  meanwhile: with a worker per core the suite kept 1.3 of 2 cores busy and took 4 min 33 s,
  with one more 1.65 and 3 min 30 s (a smaller suite). Two more is no faster: on 2 cores the
  suite of 30 Nov 2026 took 5 min 12 s with 3 workers (1.6 cores busy) and 5 min 10 s with 4
  (1.9 busy, 11 % more CPU spent). ``-n N`` sets it; ``-n 0`` runs in this process.
- What runs together (``--dist loadscope`` in ``pyproject.toml``): a module's tests on one
  worker, so its module-scoped fixtures (a recorded flight, a sweep) are made once, and the
  real autopilots' tests (``tests/integration``) all on one worker, one after the other: PX4
  takes fixed ports, and both keep time by the wall clock.
- In what order (the longest first): each run keeps how long every scope took in pytest's
  cache (``.pytest_cache``), and the next run hands the longest scope left to each worker that
  asks. In xdist's own order (most tests first) a few long modules of few tests started last
  and two workers stood idle for their last minute. A fresh clone has no such record and runs
  in xdist's order; ``-p no:cacheprovider`` too.
- In CI (``CI`` set, as GitHub Actions and ``.ci/run`` set it) the suite prints its 20
  slowest tests, so a test that grows slow shows where it is run.
"""

from __future__ import annotations

import os
from collections import OrderedDict
from typing import Any

import pytest
from xdist.scheduler import LoadScopeScheduling

ONE_WORKER = ("tests/integration/",)
"""Folders whose tests run on one worker, one after the other."""

_SECONDS_KEY = "uavtool/scope_seconds"
"""Where pytest's cache keeps each scope's seconds (setup, call and teardown) of its last run."""


def _scope(nodeid: str) -> str:
    for folder in ONE_WORKER:
        if nodeid.startswith(folder):
            return folder
    return nodeid.split("::", 1)[0]  # the module, as xdist's loadscope splits a function's


class _LongestFirst(OrderedDict[str, dict[str, bool]]):
    """xdist's queue of scopes, handing out the longest of those left (by the seconds the last
    run took; a scope without a record counts as the mean): a long module no longer starts
    last and keeps one worker busy while the others wait at the end."""

    def __init__(self, seconds: dict[str, float]) -> None:
        super().__init__()
        self._seconds = seconds
        self._unknown = sum(seconds.values()) / len(seconds) if seconds else 0.0

    def popitem(self, last: bool = True) -> tuple[str, dict[str, bool]]:
        if last or not self._seconds:
            return super().popitem(last)
        scope = max(self, key=lambda s: self._seconds.get(s, self._unknown))
        return scope, self.pop(scope)


class _Scheduling(LoadScopeScheduling):
    def __init__(self, config: pytest.Config, log: Any = None) -> None:
        super().__init__(config, log)
        cache = getattr(config, "cache", None)
        seconds = cache.get(_SECONDS_KEY, {}) if cache is not None else {}
        if isinstance(seconds, dict):
            self.workqueue = _LongestFirst(
                {k: float(v) for k, v in seconds.items() if isinstance(v, int | float)}
            )

    def _split_scope(self, nodeid: str) -> str:
        return _scope(nodeid)


def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    if config.getvalue("dist") != "loadscope":
        return None  # another --dist asked for: xdist's own
    return _Scheduling(config, log)


_spent: dict[str, float] = {}


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    _spent[_scope(report.nodeid)] = _spent.get(_scope(report.nodeid), 0.0) + report.duration


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Keep each scope's seconds for the next run's order (only where the tests are
    handed out: the controller with workers, or this process with -n 0)."""
    cache = getattr(session.config, "cache", None)
    if cache is None or hasattr(session.config, "workerinput") or not _spent:
        return
    seconds = cache.get(_SECONDS_KEY, {})
    seconds = dict(seconds) if isinstance(seconds, dict) else {}
    seconds.update({scope: round(s, 2) for scope, s in _spent.items()})
    cache.set(_SECONDS_KEY, seconds)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return cores + 1


def pytest_configure(config: pytest.Config) -> None:
    if os.environ.get("CI") and not config.option.durations:
        config.option.durations = 20
