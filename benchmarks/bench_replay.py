"""``replay --check`` of the paper golden recording vs the flight's own (simulated) duration
(goal: ≥ 50× faster and under 3 s wall) and vs simply reading every message of the file
(the floor). Also the whole CLI in a fresh process (start-up included).

    python benchmarks/bench_replay.py [RECORDING] [--quick] [--runs N]

``--quick``: one run of each (``--runs 1``).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

from uavtool.mission import Telemetry
from uavtool.recording import RecordingReader
from uavtool.replay import load_flight, replay

PAPER = Path(__file__).resolve().parents[1] / "recordings" / "golden" / "paper.mcap"


def read_all(path: Path) -> int:
    n = 0
    with RecordingReader(path) as reader:
        for _ in reader.entries():
            n += 1
    return n


def check(path: Path) -> None:
    result = replay(load_flight(path))
    assert result.identical, result.first_difference


def timed(fn, runs: int) -> list[float]:  # type: ignore[no-untyped-def]
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "recording", nargs="?", type=Path, default=PAPER, help="default: the golden paper.mcap"
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --runs 1")
    parser.add_argument("--runs", type=int, default=5, help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(runs=1)
    a = parser.parse_args()
    flight = load_flight(a.recording)
    times = [o.time_boot_ms for o in flight.observations if isinstance(o, Telemetry)]
    sim_s = (times[-1] - times[0]) / 1000.0
    messages = read_all(a.recording)
    floor = statistics.median(timed(lambda: read_all(a.recording), a.runs))
    rep = statistics.median(timed(lambda: check(a.recording), a.runs))
    cli = statistics.median(
        timed(
            lambda: subprocess.run(
                [sys.executable, "-m", "uavtool", "replay", "--check", "-q", str(a.recording)],
                check=True,
                stdout=subprocess.DEVNULL,
            ),
            max(a.runs // 2, 1),
        )
    )
    print(
        f"{a.recording.name}: {len(flight.observations)} observations, {messages} messages, "
        f"flight {sim_s:.1f} s (sim)"
    )
    print(f"  read every message (floor): {floor * 1000:7.1f} ms")
    print(
        f"  replay --check (in process): {rep * 1000:7.1f} ms  = {rep / floor:.1f}x the floor, "
        f"{sim_s / rep:.0f}x faster than the flight (goal >= 50x, < 3 s: "
        f"{'met' if sim_s / rep >= 50 and rep < 3 else 'NOT met'})"
    )
    print(
        f"  uavtool replay --check (fresh process, start-up included): {cli:.2f} s "
        f"= {sim_s / cli:.0f}x faster than the flight"
    )


if __name__ == "__main__":
    main()
