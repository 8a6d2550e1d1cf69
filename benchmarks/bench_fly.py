"""``uavtool fly`` on ``paper`` and ``uavtool replay --check`` of its golden, whole processes,
today against commit ``BASELINE`` (675267c: before the recording-speed work, issue "Recording
at the speed of the flight"), in one run, as ratios:

- ``fly`` (records to ``recordings/``), goal <= 1.0 s, and as a ratio to the baseline
  <= 0.621 (`GOAL_RATIO`: the goal over the baseline's time where the goal was set);
- ``fly --no-record``, and the recording's share of ``fly`` over it, goal <= 10 %;
- ``fly`` with each writer forced (``uavtool fly`` picks one by the machine's load: a writer
  process when a core is free, else the flight's own thread; the file is the same), today
  only;
- ``fly --no-record --rerun FILE.rrd`` (today at its default pace; the baseline needed
  ``--speedup max`` for that, and took the flight's vehicle time, ~229 s, without it);
- ``replay --check recordings/golden/paper.mcap``, goal <= 0.5 s, and as a ratio <= 0.746
  (the baseline replays its own commit's golden: the golden's format moved on since);
- ``uavtool --version``: start-up;
- and the flight alone, in this process: vehicle seconds per wall second.

The baseline's ``uavtool`` package is extracted with ``git archive`` and run from the same
virtualenv; the variants take turns in every round, so a machine whose speed drifts treats
them alike. Every command runs once first, uncounted, with Python's bytecode cache on (in a
folder of its own, whatever ``PYTHONDONTWRITEBYTECODE`` says): an installed package has its
``.pyc`` files, and compiling uavtool's ~150 modules again costs every command ~0.2 s. The
report names the machine (cores, load average before and after) and both commits.

    python benchmarks/bench_fly.py [--quick] [--runs N] [--baseline COMMIT] [--instructions]

``--instructions``: instead, each command once under valgrind's callgrind (when valgrind is
installed), counting the instructions its process and its children (the writer process)
execute: ~50x slower, but the count moves by well under 1 % between runs, where the wall
time of a command on a shared virtual machine moves by 20-40 %. It shows what a change
saves; the wall time shows what a user waits.

``--quick``: one round (``--runs 1``). The baseline commit must be in the clone (``git fetch
--unshallow`` in a shallow one). A command the baseline cannot run here is reported with its
error and no ratio: 675267c's ``fly`` (recording) fails with numpy 2.5 (the schema bug fixed
since; Python 3.12 and 3.13 here), so compare on 3.11 (numpy 2.4).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

from uavtool.recording.cores import core_to_spare
from uavtool.runner.fly import FlyConfig, fly

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "675267c"
# The goals (fly <= 1.0 s, replay --check <= 0.5 s) were set on a machine where the
# baseline's fly took 1.61 s and its --no-record 1.20 s (the figures), and its replay
# --check 0.67 s (a1c4b89's run there, whose 675267c --no-record took those 1.20 s). This
# machine's speed moves by up to 1.8x within a day, so each goal is also judged as that ratio
# to the baseline, measured in the same run.
GOAL_RATIO = {"fly": 1.0 / 1.61, "replay --check": 0.5 / 0.67}
GOLDEN = "recordings/golden/paper.mcap"
# ``uavtool ARGS`` with fly's choice of writer forced (``spare``: whether a core is free); the
# entry point's thread setting is made before numpy loads, as `uavtool` makes it
_FORCED = (
    "import sys; from uavtool import cli; cli._one_blas_thread(); "  # as `main` does, first
    "import uavtool.runner.fly as f; f.core_to_spare = lambda: {spare}; "
    "sys.argv[0] = 'uavtool'; cli.main()"
)


def extract(commit: str, into: Path) -> Path:
    """The ``uavtool`` package and the paper golden as they were at ``commit``, under ``into``
    (a plain copy, no worktree: it goes with ``into``)."""
    done = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit, "uavtool", GOLDEN],
        check=False,
        capture_output=True,
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


def uavtool(*args: str, spare: bool | None = None) -> list[str]:
    """Python's arguments for ``uavtool ARGS``; ``spare``: force fly's choice of writer."""
    if spare is None:
        return ["-m", "uavtool", *args]
    return ["-c", _FORCED.format(spare=spare), *args]


def run(
    args: list[str], *, cwd: Path, pycache: Path, pythonpath: Path | None = None
) -> tuple[float, float, str | None]:
    """(wall seconds, CPU seconds, None) of ``python ARGS`` (see `uavtool`) in a fresh
    process, or (nan, nan, why) if it failed: the last line it wrote to stderr. CPU is user +
    system time of the process, its threads and its children (the writer process), which
    other work on the machine changes much less than the wall time. Bytecode is cached under
    ``pycache``."""
    env = _env(pycache, pythonpath)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, *args],
        check=False,
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines() or [f"exit {done.returncode}"]
        return math.nan, math.nan, lines[-1]
    return wall, cpu, None


def _env(pycache: Path, pythonpath: Path | None) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(pycache)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    return env


def instructions(
    args: list[str], *, cwd: Path, pycache: Path, pythonpath: Path | None = None
) -> tuple[int, int]:
    """Instructions executed by ``python ARGS`` (callgrind's count) and by its children, in
    one run: (the process's, its children's)."""
    with tempfile.TemporaryDirectory() as out:
        proc = subprocess.Popen(
            [
                "valgrind",
                "--tool=callgrind",
                "--trace-children=yes",
                f"--callgrind-out-file={out}/%p.out",
                sys.executable,
                *args,
            ],
            cwd=cwd,
            env=_env(pycache, pythonpath),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        _, err = proc.communicate()
        if proc.returncode != 0:
            raise SystemExit(f"valgrind python {' '.join(args)} failed: {err.strip()[-300:]}")
        own = children = 0
        for path in Path(out).glob("*.out"):
            text = path.read_text(errors="replace")
            total = int(text.split("\nsummary: ", 1)[1].split()[0])
            if path.name == f"{proc.pid}.out":  # valgrind runs the program in its own process
                own = total
            else:
                children += total
        return own, children


def _runs(times: list[float]) -> str:
    return ", ".join(f"{t:.2f}" for t in times)


def _goal(value: float, limit: float) -> str:
    return "met" if value <= limit else "NOT met"


def _scaled(today: dict[str, list[float]], then: dict[str, list[float]], name: str) -> str:
    """The goal of ``name`` as a ratio to the baseline (`GOAL_RATIO`), judged."""
    ratio = statistics.median(today[name]) / statistics.median(then[name])
    limit = GOAL_RATIO[name]
    return f"as a ratio to the baseline (<= {limit:.3f}): {_goal(ratio, limit)} ({ratio:.3f})"


def _commit(rev: str) -> str:
    """The short hash of ``rev``; for HEAD, '+ changes' when the work tree differs."""
    git = ["git", "-C", str(ROOT)]
    short = subprocess.run(
        [*git, "rev-parse", "--short", rev], check=False, capture_output=True, text=True
    )
    name = short.stdout.strip() or rev
    if rev == "HEAD":
        dirty = subprocess.run([*git, "diff", "--quiet", "HEAD", "--", "uavtool"], check=False)
        name += " + changes" if dirty.returncode else ""
    return name


def _writer(spare: bool) -> str:
    return "a writer process" if spare else "the flight's thread"


def _load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --runs 1")
    parser.add_argument("--runs", type=int, default=5, help="rounds (default: %(default)s)")
    parser.add_argument("--baseline", default=BASELINE, help="the commit to compare with")
    parser.add_argument(
        "--instructions",
        action="store_true",
        help="count instructions under valgrind's callgrind instead of timing (slow)",
    )
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(runs=1)
    args = parser.parse_args()
    n = args.runs
    golden = str(ROOT / GOLDEN)
    with tempfile.TemporaryDirectory() as tmp_text:
        tmp = Path(tmp_text)
        base = extract(args.baseline, tmp / "baseline")
        rrd = str(tmp / "live.rrd")
        # name -> (today's arguments, the baseline's or None: not run there)
        commands: dict[str, tuple[list[str], list[str] | None]] = {
            "fly": (uavtool("fly", "-q"), uavtool("fly", "-q")),
            "fly --no-record": (
                uavtool("fly", "-q", "--no-record"),
                uavtool("fly", "-q", "--no-record"),
            ),
            "fly, writer process": (uavtool("fly", "-q", spare=True), None),
            "fly, writer in thread": (uavtool("fly", "-q", spare=False), None),
            "fly --rerun FILE.rrd": (
                uavtool("fly", "-q", "--no-record", "--rerun", rrd),
                uavtool("fly", "-q", "--no-record", "--rerun", rrd, "--speedup", "max"),
            ),
            "replay --check": (
                uavtool("replay", "--check", golden),
                uavtool("replay", "--check", str(base / GOLDEN)),
            ),
            "--version": (uavtool("--version"), uavtool("--version")),
        }
        today: dict[str, list[float]] = {k: [] for k in commands}
        then: dict[str, list[float]] = {k: [] for k in commands}
        today_cpu: dict[str, list[float]] = {k: [] for k in commands}
        then_cpu: dict[str, list[float]] = {k: [] for k in commands}
        failed: dict[str, str] = {}  # the baseline's failures (e.g. on a newer Python)
        if args.instructions:
            count_instructions(commands, tmp, base, args.baseline)
            return
        load_before, spare_before = _load(), core_to_spare()
        for i in range(n + 1):  # round 0 fills the bytecode caches: not counted
            for name, (now_args, base_args) in commands.items():
                t, cpu, why = run(now_args, cwd=tmp, pycache=tmp / "pyc-today")
                if why is not None:
                    raise SystemExit(f"uavtool {' '.join(now_args)} failed: {why}")
                t_base = cpu_base = math.nan
                if base_args is not None:
                    t_base, cpu_base, why = run(
                        base_args, cwd=tmp, pycache=tmp / "pyc-base", pythonpath=base
                    )
                    if why is not None:
                        failed[name] = why
                if i:
                    today[name].append(t)
                    then[name].append(t_base)
                    today_cpu[name].append(cpu)
                    then_cpu[name].append(cpu_base)
        load_after, spare_after = _load(), core_to_spare()
        size = max(p.stat().st_size for p in (tmp / "recordings").glob("*.mcap"))
        flights = []
        for i in range(n):  # the flight alone, in this process: no start-up, recording on
            s = fly(FlyConfig(record=tmp / f"inproc{i}.mcap"))
            flights.append((s.vehicle_time_s / s.flight_wall_s, s.vehicle_time_s, s.flight_wall_s))
    med = statistics.median
    python = ".".join(str(v) for v in sys.version_info[:3])
    print(f"uavtool (paper, defaults, {n} rounds, fresh processes, variants take turns)")
    print(
        f"  today {_commit('HEAD')}, baseline {_commit(args.baseline)}; Python {python}, "
        f"{os.cpu_count()} cores, load average {load_before} before, {load_after} after"
    )
    print(
        "  fly's writer by the load: "
        + ", ".join(_writer(spare) for spare in (spare_before, spare_after))
        + " (before, after)"
    )
    for what, now_s, base_s in (("wall", today, then), ("CPU", today_cpu, then_cpu)):
        print(f"  {what:<22} {'today':>8} {args.baseline:>8} {'ratio':>7}   runs today | baseline")
        for name in commands:
            a, b = med(now_s[name]), med(base_s[name])
            if math.isnan(b):  # not run on the baseline
                print(f"  {name:<22} {a:7.2f}s {'-':>8} {'-':>7}   {_runs(now_s[name])}")
                continue
            print(
                f"  {name:<22} {a:7.2f}s {b:7.2f}s {a / b:6.3f}x   "
                f"{_runs(now_s[name])} | {_runs(base_s[name])}"
            )
    for name, why in failed.items():  # no ratio for it (nan): say why
        print(f"  {args.baseline} failed '{name}' on Python {python}: {why}")
    fly_s, bare_s = med(today["fly"]), med(today["fly --no-record"])
    base_share = med(then["fly"]) / med(then["fly --no-record"]) - 1.0
    base_cpu_share = med(then_cpu["fly"]) / med(then_cpu["fly --no-record"]) - 1.0
    check_s = med(today["replay --check"])
    print(
        f"  goal fly <= 1.0 s: {_goal(fly_s, 1.0)} ({fly_s:.2f} s); {_scaled(today, then, 'fly')}"
    )
    print(
        f"  recording's share over --no-record (goal <= 10 %), wall and CPU: baseline "
        f"{base_share * 100:+.1f} %, {base_cpu_share * 100:+.1f} %; file {size / 1e6:.2f} MB"
    )
    print(
        "    (the median of each round's ratio to that round's --no-record: the pairs ran "
        "side by side; then the ratio of the medians)"
    )
    for name in ("fly", "fly, writer process", "fly, writer in thread"):
        paired = _paired(today[name], today["fly --no-record"])
        cpu_paired = _paired(today_cpu[name], today_cpu["fly --no-record"])
        share = med(today[name]) / bare_s - 1.0
        cpu_share = med(today_cpu[name]) / med(today_cpu["fly --no-record"]) - 1.0
        print(
            f"    {name:<22} {paired * 100:+6.1f} %, {cpu_paired * 100:+6.1f} % "
            f"(of medians {share * 100:+.1f} %, {cpu_share * 100:+.1f} %): {_goal(paired, 0.10)}"
        )
    print(
        f"  goal replay --check <= 0.5 s: {_goal(check_s, 0.5)} ({check_s:.2f} s); "
        f"{_scaled(today, then, 'replay --check')}"
    )
    rate, vehicle_s, wall_s = sorted(flights)[n // 2]
    print(
        f"  the flight alone, in-process, recording on: {vehicle_s:.1f} vehicle s in "
        f"{wall_s:.2f} s wall = {rate:.0f}x (median of {n})"
    )


def _paired(runs: list[float], bare: list[float]) -> float:
    """The median of each round's ratio of ``runs`` to ``bare``, less one: a share."""
    return statistics.median(a / b for a, b in zip(runs, bare, strict=True)) - 1.0


def count_instructions(
    commands: dict[str, tuple[list[str], list[str] | None]], tmp: Path, base: Path, baseline: str
) -> None:
    """Each command once under callgrind, today and on the baseline (bytecode cached first),
    and the ratios. The baseline writes its recording on the flight's thread: both of today's
    writers are compared with its `fly` (the writer process: both processes together)."""
    if shutil.which("valgrind") is None:
        raise SystemExit("--instructions needs valgrind (Debian: apt install valgrind)")
    # today's command -> the baseline's
    pairs = {
        "fly --no-record": "fly --no-record",
        "fly, writer process": "fly",
        "fly, writer in thread": "fly",
        "replay --check": "replay --check",
        "--version": "--version",
    }
    today: dict[str, tuple[int, int]] = {}
    then: dict[str, tuple[int, int]] = {}
    for name, base_name in pairs.items():
        now_args = commands[name][0]
        run(now_args, cwd=tmp, pycache=tmp / "pyc-today")  # bytecode caches, as timed runs have
        today[name] = instructions(now_args, cwd=tmp, pycache=tmp / "pyc-today")
        base_args = commands[base_name][1]
        if base_args is not None and base_name not in then:
            run(base_args, cwd=tmp, pycache=tmp / "pyc-base", pythonpath=base)
            then[base_name] = instructions(
                base_args, cwd=tmp, pycache=tmp / "pyc-base", pythonpath=base
            )
    python = ".".join(str(v) for v in sys.version_info[:3])
    print("uavtool (paper, defaults): instructions executed, callgrind, one run each")
    print(f"  today {_commit('HEAD')}, baseline {_commit(baseline)}; Python {python}")
    print(f"  {'G = 1e9':<22} {'today':>16} {baseline:>9} {'ratio':>7}   (+ the writer process)")
    for name, base_name in pairs.items():
        own, child = today[name]
        shown = f"{own / 1e9:.3f} G" + (f" + {child / 1e9:.3f}" if child else "")
        b = sum(then[base_name])
        print(f"  {name:<22} {shown:>16} {b / 1e9:7.3f} G {(own + child) / b:6.3f}x")
    bare = sum(today["fly --no-record"])
    for name in ("fly, writer process", "fly, writer in thread"):
        own, child = today[name]
        print(
            f"  recording's work over --no-record, {name[5:]}: the flight's process "
            f"{(own - bare) / bare * 100:+.1f} %, in all {(own + child - bare) / bare * 100:+.1f} %"
        )
    base_share = sum(then["fly"]) / sum(then["fly --no-record"]) - 1
    print(f"  {baseline}'s (on the flight's thread): {base_share * 100:+.1f} %")


if __name__ == "__main__":
    main()
