"""Suite-wide settings.

- Workers (pytest-xdist, ``-n auto`` in ``pyproject.toml``): two more than this process may
  use cores. Many tests wait on real time (a ground station's heartbeat each second, a
  real-time link, a browser drawing, a recorder's ``--duration``) and leave their core idle
  meanwhile. The modules that do little else (``ON_THE_CLOCK``) run one after the other as
  one scope, which keeps one worker; the others share the cores. On 2 cores (30 Nov 2026):
  3 workers, each module its own scope, 5 min 12 s (1.6 cores busy); 4 workers so, 5 min 10 s
  (1.9 busy, and 11 % more CPU spent: four flights at once on two cores); 4 workers with the
  waiting modules as one scope, 4 min 28 s and 4 min 52 s in two runs (1.9 busy), 4 min 51 s
  with no record of the scopes' seconds (below). ``-n N`` sets it; ``-n 0`` runs in this
  process.
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

ON_THE_CLOCK = (
    "tests/recorder/test_stops.py",
    "tests/recorder/test_fleet.py",
    "tests/runner/test_lossy_link.py",
    "tests/sitl/test_udp_admission.py",
    "tests/sitl/test_commands.py",
    "tests/sitl/test_security.py",
)
"""Modules that mostly wait on the wall clock (a recorder's ``--duration``, a vehicle at 10x
or 20x, a flood of ground stations expiring): one scope, one after the other on one worker,
which then leaves the cores to the others."""

_SECONDS_KEY = "uavtool/scope_seconds"
"""Where pytest's cache keeps each scope's seconds (setup, call and teardown) of its last run."""


def _scope(nodeid: str) -> str:
    for folder in ONE_WORKER:
        if nodeid.startswith(folder):
            return folder
    if nodeid.startswith(ON_THE_CLOCK):
        return "on the clock"
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
    scope = _scope(report.nodeid)
    _spent[scope] = _spent.get(scope, 0.0) + report.duration


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
    return cores + 2


def pytest_configure(config: pytest.Config) -> None:
    if os.environ.get("CI") and not config.option.durations:
        config.option.durations = 20
