"""Wall time of the default ``uavtool fly`` on ``paper`` (goal: < 20 s including start-up), and
the recording's overhead against ``--no-record`` in the same run (goal: ≤ 10 %).

Each variant runs as a fresh ``uavtool fly`` process (start-up included), alternating, several
times; medians are compared. Run: ``python benchmarks/bench_fly.py [--runs N]``.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run_once(args: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "uavtool", "fly", "-q", *args],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=3)
    n = parser.parse_args().runs
    with tempfile.TemporaryDirectory() as tmp:
        recorded: list[float] = []
        bare: list[float] = []
        for i in range(n):
            recorded.append(run_once(["--record", str(Path(tmp) / f"r{i}.mcap")]))
            bare.append(run_once(["--no-record"]))
        size = (Path(tmp) / "r0.mcap").stat().st_size
    rec, nor = statistics.median(recorded), statistics.median(bare)
    print(f"uavtool fly (paper, defaults, {n} runs each, fresh processes)")
    print(f"  recorded:   median {rec:6.2f} s  (runs {', '.join(f'{t:.2f}' for t in recorded)})")
    print(f"  --no-record median {nor:6.2f} s  (runs {', '.join(f'{t:.2f}' for t in bare)})")
    print(f"  goal < 20 s: {'met' if rec < 20 else 'NOT met'}")
    print(
        f"  recording overhead: {rec / nor:.3f}x of --no-record ({(rec / nor - 1) * 100:+.1f} %), "
        f"goal <= 10 %: {'met' if rec / nor <= 1.10 else 'NOT met'}; file {size / 1e6:.2f} MB"
    )


if __name__ == "__main__":
    main()
