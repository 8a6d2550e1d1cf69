"""Whether a writer process would find a core of its own (`core_to_spare`): measured from
``/proc/stat`` over the last seconds, not read from a load average a minute old."""

from __future__ import annotations

import os
import time
from pathlib import Path


def _cpu_sample() -> tuple[float, float, float] | None:
    """(now, seconds of CPU the whole machine spent busy, seconds this process spent) from
    ``/proc/stat``, or None where there is none."""
    try:
        with Path("/proc/stat").open("rb") as stat:
            fields = stat.readline().split()
        ticks = [int(v) for v in fields[1:9]]  # user nice system idle iowait irq softirq steal
    except (OSError, ValueError):
        return None
    if fields[:1] != [b"cpu"] or len(ticks) < 5:
        return None
    busy_s = (sum(ticks) - ticks[3] - ticks[4]) / os.sysconf("SC_CLK_TCK")
    mine = os.times()
    return time.monotonic(), busy_s, mine.user + mine.system


_last_sample = _cpu_sample()  # from this module's import: what the machine did meanwhile
SAMPLE_S = (0.05, 10.0)
"""The window `core_to_spare` measures the machine over: from its last call (or this
module's import, early in a command's start-up) to now, when that is this many seconds;
else the load average decides."""


def core_to_spare() -> bool:
    """Whether a writer process would find a core of its own: at least two cores for this
    process, and other processes busy for less than the cores less one and a half (the
    flight takes one; half a core is left for the writer) since the last call or this
    module's import, 0.05-10 s ago; without that measure, a load average of the last minute
    below the cores less one half. A load average lags a minute: after a burst of commands
    it still counts those that ended. Without a spare core a writer process only adds its
    work to a busy machine, and the flight waits for it at the end."""
    global _last_sample  # noqa: PLW0603 - the window runs from call to call
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return False
    if cores < 2:
        return False
    before, now = _last_sample, _cpu_sample()
    _last_sample = now
    if before is not None and now is not None:
        span_s = now[0] - before[0]
        if SAMPLE_S[0] <= span_s <= SAMPLE_S[1]:
            others = ((now[1] - before[1]) - (now[2] - before[2])) / span_s  # cores, busy
            return others < (os.cpu_count() or cores) - 1.5
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return False
    return load < cores - 0.5
