"""Throughput of ``uavtool sweep`` and ``uavtool replay DIR`` on Dask against plain loops.

    python benchmarks/bench_sweep.py [--quick] [--flights 24] [--replays 100] [--tasks 2000]

- flights per minute with a 1-worker and a 2-worker LocalCluster (goal: ≥ 1.7× with 2 on a
  2-core machine), end to end (cluster start-up and shutdown included);
- the sweep's overhead against the same flights run one after another in this process by
  the same task function (goal: ≤ 10 %);
- ``replay --check`` over REPLAYS recordings (the sweep's, repeated) on 2 workers against a
  serial loop;
- for planning past this machine: the scheduler's cost per task (no-op tasks on 2 workers),
  the start-up of a cluster, and the recording size per flight.

Flights are of the ``paper`` scene with seeds 0..FLIGHTS-1 (one grid dimension), the same in
every variant; the tables of the 1- and 2-worker sweeps are compared (apart from wall time
and worker) to show the figures are of the same work. ``--quick``: every row on a few flights
(``--flights 2 --replays 4 --tasks 100``).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from uavtool.cli.fly import EXIT_CODES
from uavtool.sweep import load_spec, plan_flights, run_sweep
from uavtool.sweep.cluster import open_client
from uavtool.sweep.plan import dimension_keys
from uavtool.sweep.replay import replay_many, replay_recording
from uavtool.sweep.table import RUN_DEPENDENT
from uavtool.sweep.task import run_flight


def _noop(x: int) -> int:
    return x


def timed_sweep(
    spec_path: Path, out: Path, workers: int
) -> tuple[float, float, list[dict[str, object]]]:
    """(elapsed s, mean wall s of one flight inside its task, reproducible rows)."""
    t0 = time.perf_counter()
    result = run_sweep(
        load_spec(spec_path), exit_codes=EXIT_CODES, out=out, workers=workers, plots=False
    )
    elapsed_s = time.perf_counter() - t0
    in_task_s = sum(float(r["wall_s"]) for r in result.rows) / len(result.rows)
    return (
        elapsed_s,
        in_task_s,
        [{k: v for k, v in r.items() if k not in RUN_DEPENDENT} for r in result.rows],
    )


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="the smallest run: --flights 2 --replays 4 --tasks 100",
    )
    parser.add_argument("--flights", type=int, default=24, help="default: %(default)s")
    parser.add_argument("--replays", type=int, default=100, help="default: %(default)s")
    parser.add_argument("--tasks", type=int, default=2000, help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(flights=2, replays=4, tasks=100)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp_text:
        tmp = Path(tmp_text)
        spec_path = tmp / "bench.toml"
        spec_path.write_text(
            '[scenes]\nbuiltin = ["paper"]\n[grid]\n'
            f"seed = {{ first = 0, count = {args.flights} }}\n"
        )
        n = args.flights
        load = os.getloadavg()[0]
        print(f"{n} flights of 'paper' (seeds 0..{n - 1}), {os.cpu_count()} cores, load {load:.1f}")

        spec = load_spec(spec_path)
        keys = dimension_keys(spec)
        serial_root = tmp / "serial"
        t0 = time.perf_counter()
        for flight in plan_flights(spec):
            run_flight(flight, str(serial_root), input_keys=keys, exit_codes=EXIT_CODES)
        serial_s = time.perf_counter() - t0
        print(
            f"  serial loop, one process  {serial_s:7.1f} s  {60 * n / serial_s:6.1f} flights/min"
        )

        one_s, one_task_s, one_rows = timed_sweep(spec_path, tmp / "one", 1)
        print(
            f"  sweep, 1 worker           {one_s:7.1f} s  {60 * n / one_s:6.1f} flights/min"
            f"  ({one_task_s:.2f} s per flight inside its task)"
        )
        two_s, two_task_s, two_rows = timed_sweep(spec_path, tmp / "two", 2)
        print(
            f"  sweep, 2 workers          {two_s:7.1f} s  {60 * n / two_s:6.1f} flights/min"
            f"  ({two_task_s:.2f} s per flight inside its task: more than with 1 worker only "
            "when the cores are busy with other work)"
        )
        errors = {str(r["error"]) for r in one_rows + two_rows if r["error"]}
        assert not errors, f"flights raised: {errors}"
        assert one_rows == two_rows, "the 1- and 2-worker tables differ"
        print(f"  2 workers / 1 worker      {one_s / two_s:7.2f}x  (goal >= 1.7x)")
        print(
            f"  overhead, 1 worker vs serial loop  {100 * (one_s / serial_s - 1):+.1f} %"
            "  (goal <= 10 %)"
        )

        t0 = time.perf_counter()
        with open_client(workers=2):
            started_s = time.perf_counter() - t0
        cycle_s = time.perf_counter() - t0
        print(f"  LocalCluster(2) start {started_s:.1f} s, start+close {cycle_s:.1f} s")
        with open_client(workers=2) as client:
            client.gather(client.map(_noop, range(50)))  # warm
            t0 = time.perf_counter()
            client.gather(client.map(_noop, range(args.tasks)))
            task_s = (time.perf_counter() - t0) / args.tasks
        print(
            f"  scheduler: {args.tasks} no-op tasks on 2 workers, {1e3 * task_s:.2f} ms per task "
            f"({1 / task_s:.0f} tasks/s)"
        )
        sizes = [p.stat().st_size for p in (tmp / "two").rglob("*.mcap")]
        per_flight_s = two_s * 2 / n
        print(
            f"  recording {sum(sizes) / len(sizes) / 1e6:.2f} MB per flight; "
            f"{per_flight_s:.2f} s of one worker per flight (2-worker sweep)"
        )

        recordings = sorted((tmp / "two").rglob("*.mcap"))
        folder = tmp / "replays"
        folder.mkdir()
        paths = []
        for i in range(args.replays):
            path = folder / f"{i:04d}.mcap"
            os.link(recordings[i % len(recordings)], path)
            paths.append(path)
        t0 = time.perf_counter()
        serial_rows = [replay_recording(str(p), {}, False) for p in paths]
        replay_serial_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        batch = replay_many(paths, overrides={}, workers=2)
        replay_batch_s = time.perf_counter() - t0
        identical = sum(r["result"] == "identical" for r in batch.rows)
        assert identical == len(paths) == sum(r["result"] == "identical" for r in serial_rows)
        print(
            f"  replay --check x{len(paths)}: serial {replay_serial_s:.1f} s, "
            f"2 workers {replay_batch_s:.1f} s ({replay_serial_s / replay_batch_s:.2f}x), "
            f"all identical"
        )
        print(f"  load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
