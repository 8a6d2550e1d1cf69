"""Converting a recording for Rerun: `uavtool view REC --save out.rrd` (goal: paper < 5 s).

    python benchmarks/bench_view.py [RECORDING] [--quick] [--runs N]

Prints, for the recording (default: the golden paper mission):
- the whole command as a user runs it (a fresh process: imports, scene meshes, the file);
- the conversion in-process (median of N), and the part of it spent reading the MCAP;
- telemetry sent as columns (what the viewer does) against one `log` call per sample.

``--quick``: one run of each (``--runs 1``).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import rerun as rr

from uavtool.recording import RecordingReader
from uavtool.view import view
from uavtool.view.paths import VEHICLE_TIME
from uavtool.view.source import IMAGE, OBSERVATIONS, OUTPUTS, STATUSTEXT

ROOT = Path(__file__).resolve().parents[1]


def _median_s(fn: Callable[[], object], runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _read(path: Path) -> int:
    n = 0
    with RecordingReader(path) as reader:
        for _ in reader.entries([OBSERVATIONS, OUTPUTS, IMAGE, STATUSTEXT]):
            n += 1
    return n


def _telemetry(path: Path) -> list[dict[str, Any]]:
    with RecordingReader(path) as reader:
        return [
            e.value.payload
            for e in reader.entries([OBSERVATIONS])
            if e.value.payload["type"] == "Telemetry" and e.value.payload["time_boot_ms"] > 0
        ]


def _log_rows(samples: list[dict[str, Any]], out: Path) -> None:
    rec = rr.RecordingStream("bench", recording_id="rows")
    rec.save(out)
    for s in samples:
        rec.set_time(
            VEHICLE_TIME, duration=np.timedelta64(int(s["time_boot_ms"]) * 1_000_000, "ns")
        )
        rec.log("altitude_m", rr.Scalars([s["pos_enu_m"][2]]))
    rec.disconnect()


def _log_columns(samples: list[dict[str, Any]], out: Path) -> None:
    rec = rr.RecordingStream("bench", recording_id="columns")
    rec.save(out)
    t = np.array([int(s["time_boot_ms"]) * 1_000_000 for s in samples], dtype="timedelta64[ns]")
    alt = np.array([s["pos_enu_m"][2] for s in samples])
    rec.send_columns(
        "altitude_m",
        indexes=[rr.TimeColumn(VEHICLE_TIME, duration=t)],
        columns=rr.Scalars.columns(scalars=alt),
    )
    rec.disconnect()


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "recording",
        nargs="?",
        type=Path,
        default=ROOT / "recordings/golden/paper.mcap",
        help="default: the golden paper.mcap",
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --runs 1")
    parser.add_argument("--runs", type=int, default=3, help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(runs=1)
    args = parser.parse_args()
    path: Path = args.recording
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.rrd"
        cmd = [sys.executable, "-m", "uavtool", "view", str(path), "--save", str(out)]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        cli_s = time.perf_counter() - t0
        counts = view(path, save=out).counts  # warm: imports done, meshes' libraries loaded
        convert_s = _median_s(lambda: view(path, save=out), args.runs)
        read_s = _median_s(lambda: _read(path), args.runs)
        size_mb = out.stat().st_size / 1e6
        samples = _telemetry(path)
        rows_s = _median_s(lambda: _log_rows(samples, Path(tmp) / "rows.rrd"), args.runs)
        cols_s = _median_s(lambda: _log_columns(samples, Path(tmp) / "cols.rrd"), args.runs)
    print(f"recording        {path} ({path.stat().st_size / 1e6:.2f} MB)")
    print(
        f"content          {counts.frames} frames, {counts.telemetry} telemetry samples, "
        f"{counts.shapes} shapes, {counts.models} model"
    )
    print(f"uavtool view     {cli_s:.2f} s end to end (fresh process), goal < 5 s")
    print(
        f"convert          {convert_s:.2f} s in-process (median of {args.runs}), "
        f".rrd {size_mb:.2f} MB"
    )
    print(f"  reading MCAP   {read_s:.2f} s of it")
    print(
        f"telemetry        columns {cols_s * 1e3:.1f} ms vs one log per sample "
        f"{rows_s * 1e3:.1f} ms ({rows_s / cols_s:.0f}x), {len(samples)} samples of one series"
    )


if __name__ == "__main__":
    main()
