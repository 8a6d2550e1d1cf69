"""The default ``uavtool fly`` on ``paper``, end to end in a fresh process, in lockstep against
the threaded, wall-paced mode it replaced (goal: ≤ 2.0 s wall on a 2-core machine); the flight
itself in vehicle seconds per wall second with recording on (goal: ≥ 150x); and the
recording's overhead against ``--no-record``.

The baseline is the code of commit ``BASELINE`` (the last one before lockstep: the built-in
SITL in its own thread at speed-up 30), extracted with ``git archive`` and run from the same
virtualenv; the variants take turns in every round, so a machine whose speed drifts treats
them alike.

    python benchmarks/bench_fly.py [--quick] [--runs N] [--baseline COMMIT]

``--quick``: one round (``--runs 1``), every variant and figure still printed. The baseline
commit must be in the clone (``git fetch --unshallow`` in a shallow one).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

from uavtool.runner.fly import FlyConfig, fly

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "48e7487"
_SUMMARY = re.compile(r"flight\s+([\d.]+) s sim.*?([\d.]+) s wall")


def extract(commit: str, into: Path) -> Path:
    """The ``uavtool`` package as it was at ``commit``, under ``into`` (a plain copy, no
    worktree: it goes with ``into``)."""
    done = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit, "uavtool"], check=False, capture_output=True
    )
    if done.returncode != 0:
        why = done.stderr.decode(errors="replace").strip()
        raise SystemExit(
            f"the baseline commit {commit} cannot be read from {ROOT}: {why}\n"
            "(a shallow clone lacks it: git fetch --unshallow)"
        )
    data = done.stdout
    with tarfile.open(fileobj=BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return into


def run_fly(args: list[str], *, cwd: Path, pythonpath: Path | None = None) -> tuple[float, str]:
    """(wall seconds, stdout) of ``uavtool fly ARGS`` in a fresh process."""
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "uavtool", "fly", "-q", *args],
        check=True,
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
    )
    return time.perf_counter() - t0, done.stdout


def _rate(stdout: str) -> float:
    """Vehicle seconds per wall second from the printed summary (flight time / fly()'s wall)."""
    m = _SUMMARY.search(stdout)
    return float(m.group(1)) / max(float(m.group(2)), 1e-3) if m else float("nan")


def _runs(times: list[float]) -> str:
    return ", ".join(f"{t:.2f}" for t in times)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --runs 1")
    parser.add_argument("--runs", type=int, default=5, help="rounds (default: %(default)s)")
    parser.add_argument("--baseline", default=BASELINE, help="commit of the threaded mode")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(runs=1)
    args = parser.parse_args()
    n = args.runs
    with tempfile.TemporaryDirectory() as tmp_text:
        tmp = Path(tmp_text)
        base = extract(args.baseline, tmp / "baseline")
        lock, thread, bare = [], [], []
        lock_rates, thread_rates = [], []
        for _ in range(n):  # the default command, as a user runs it: records to recordings/
            t, out = run_fly([], cwd=tmp)
            lock.append(t)
            lock_rates.append(_rate(out))
            t, out = run_fly([], cwd=tmp, pythonpath=base)
            thread.append(t)
            thread_rates.append(_rate(out))
            bare.append(run_fly(["--no-record"], cwd=tmp)[0])
        size = max(p.stat().st_size for p in (tmp / "recordings").glob("*.mcap"))
        flights = []
        for i in range(n):  # the flight alone, in this process: no start-up, recording on
            s = fly(FlyConfig(record=tmp / f"inproc{i}.mcap"))
            flights.append((s.vehicle_time_s / s.flight_wall_s, s.vehicle_time_s, s.flight_wall_s))
    med = statistics.median
    lo, th, nr = med(lock), med(thread), med(bare)
    rate, vehicle_s, wall_s = sorted(flights)[n // 2]
    print(f"uavtool fly (paper, defaults, {n} rounds, fresh processes, variants take turns)")
    print(f"  threaded, {args.baseline} (speed-up 30): median {th:5.2f} s  ({_runs(thread)})")
    print(f"  lockstep (speed-up max):        median {lo:5.2f} s  ({_runs(lock)})")
    print(
        f"  ratio lockstep / threaded: {lo / th:.3f}x ({th / lo:.1f}x faster); "
        f"goal <= 2.0 s: {'met' if lo <= 2.0 else 'NOT met'}"
    )
    print(
        f"  vehicle s per wall s, fly() as printed: lockstep {med(lock_rates):.0f}x, "
        f"threaded {med(thread_rates):.0f}x ({med(lock_rates) / med(thread_rates):.1f}x)"
    )
    print(
        f"  the flight alone, in-process, recording on: {vehicle_s:.1f} vehicle s in "
        f"{wall_s:.2f} s wall = {rate:.0f}x (median of {n}); goal >= 150x: "
        f"{'met' if rate >= 150 else 'NOT met'}"
    )
    print(
        f"  recording overhead: {lo / nr:.3f}x of --no-record ({nr:.2f} s; "
        f"{(lo / nr - 1) * 100:+.1f} %); file {size / 1e6:.2f} MB"
    )


if __name__ == "__main__":
    main()
