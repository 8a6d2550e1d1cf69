"""Every benchmark in its quickest mode, so none goes stale: what CI runs.

    python benchmarks/run_all_quick.py [--verbose] [--timeout 600] [NAME ...]

Each ``benchmarks/bench_*.py`` (or each NAME: ``fly``, ``bench_fly`` or ``bench_fly.py``),
one at a time, with this Python (``sys.executable``) from the repository's root: first
``--help``, which must print ``usage:`` and exit 0 within 10 s without running anything, then
``--quick``, which must exit 0 (within ``--timeout`` seconds). Prints one line per benchmark
with the wall times and PASS or FAIL, then the last 30 lines of the output of each that
failed; exits 1 if any failed.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
HELP_TIMEOUT_S = 10.0
TAIL_LINES = 30


def run(script: Path, flag: str, timeout_s: float) -> tuple[int | None, float, str]:
    """(exit code, None on a timeout; wall seconds; stdout and stderr) of ``script flag``.

    The benchmark runs in a session of its own: on a timeout it is killed with every process
    it started (Dask workers, flights), and nothing else."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, str(script), flag],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
        text=True,
        errors="replace",
        start_new_session=True,
    )
    try:
        out, _ = proc.communicate(timeout=timeout_s)
        code: int | None = proc.returncode
    except subprocess.TimeoutExpired:
        _kill(proc)
        out, _ = proc.communicate()
        code = None
    except BaseException:  # Ctrl-C here does not reach its session: end it too
        _kill(proc)
        raise
    return code, time.perf_counter() - t0, out


def _kill(proc: subprocess.Popen[str]) -> None:
    """The benchmark and every process still in its session."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)


def help_problem(code: int | None, out: str) -> str:
    """What is wrong with a ``--help`` run, or nothing."""
    if code is None:
        return f"--help took over {HELP_TIMEOUT_S:g} s"
    if code != 0:
        return f"--help exited {code}"
    if "usage:" not in out:
        return "--help printed no usage: line"
    return ""


def select(names: list[str]) -> list[Path]:
    every = sorted(HERE.glob("bench_*.py"))
    if not names:
        return every
    by_name = {p.stem.removeprefix("bench_"): p for p in every}
    chosen = []
    for name in names:
        key = Path(name).stem.removeprefix("bench_")
        if key not in by_name:
            known = ", ".join(sorted(by_name))
            raise ValueError(f"no benchmark {name!r} (known: {known})")
        chosen.append(by_name[key])
    return chosen


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("names", nargs="*", metavar="NAME", help="default: every benchmark")
    parser.add_argument(
        "--timeout", type=float, default=600.0, help="seconds per --quick run (default: 600)"
    )
    parser.add_argument("--verbose", action="store_true", help="print every benchmark's output")
    args = parser.parse_args()
    try:
        scripts = select(args.names)
    except ValueError as exc:
        parser.error(str(exc))
    print(f"{len(scripts)} benchmarks, {sys.executable} (Python {sys.version.split()[0]})")
    failed: list[tuple[str, str, str]] = []
    t_all = time.perf_counter()
    for script in scripts:
        code, help_s, out = run(script, "--help", HELP_TIMEOUT_S)
        why = help_problem(code, out)
        if why:
            print(f"  {script.name:<36s} help {help_s:5.1f} s  {'':16s}FAIL ({why})", flush=True)
            failed.append((script.name, why, out))
            continue
        code, quick_s, out = run(script, "--quick", args.timeout)
        if args.verbose:
            print(out, end="" if out.endswith("\n") else "\n")
        if code == 0:
            status = "PASS"
        else:
            why = (
                f"--quick took over {args.timeout:g} s"
                if code is None
                else f"--quick exited {code}"
            )
            status = f"FAIL ({why})"
            failed.append((script.name, why, out))
        print(
            f"  {script.name:<36s} help {help_s:5.1f} s  quick {quick_s:6.1f} s  {status}",
            flush=True,
        )
    total_s = time.perf_counter() - t_all
    for name, why, out in failed:
        tail = out.rstrip("\n").splitlines()[-TAIL_LINES:]
        print(f"\n==== {name}: {why}; its last {len(tail)} lines:")
        print("\n".join(tail))
    passed = len(scripts) - len(failed)
    print(f"\n{passed}/{len(scripts)} passed in {total_s:.0f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
