"""What checking every chunk's CRC costs ``uavtool info`` on a ~100 MB recording.

    python benchmarks/bench_info_verify.py [--quick] [--size-mb 100] [--repeat 5]

Writes a recording shaped like a long flight (MAVLink telemetry both ways at 50 Hz, one
~20 KiB camera frame per second of log time, zstd chunks of one second) of about the given
size, then times `summarize` with every chunk read and checked (``uavtool info``, the
default) and from the summary alone (``uavtool info --no-verify``), and the whole command
both ways in a fresh process. Prints medians and the ratios. On demand, and in CI with
``--quick`` (``--size-mb 5 --repeat 2``: the same rows on a small file).
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

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from uavtool.recording import CompressedImage, Direction, RecordingWriter, summarize

T0_NS = 1_700_000_000_000_000_000

_FRAME_BYTES = 20 * 1024
_RATE_HZ = 50


def _mavlink_frames(n: int) -> list[tuple[Direction, bytes]]:
    vehicle = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    gcs = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    out = []
    for i in range(n):
        if i % 5 == 0:
            msg = mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 4, 3)
            out.append((Direction.OUT, bytes(msg.pack(gcs))))
        else:
            msg = mavlink.MAVLink_global_position_int_message(
                i * 20, 473977420 + i, 85455940, 500000, 45000 + i, 10, -5, 0, 9000
            )
            out.append((Direction.IN, bytes(msg.pack(vehicle))))
    return out


def write_recording(path: Path, size_mb: float) -> int:
    """A flight-like recording of about ``size_mb`` MB; returns its message count."""
    rng = np.random.default_rng(7)
    frames = _mavlink_frames(50)
    # incompressible "PNG" bytes, as real frames nearly are
    images = [rng.integers(0, 256, _FRAME_BYTES, dtype=np.uint8).tobytes() for _ in range(16)]
    step_ns = 1_000_000_000 // _RATE_HZ
    with RecordingWriter(path, fsync=False) as writer:
        i = 0
        while True:
            t = T0_NS + i * step_ns
            direction, frame = frames[i % len(frames)]
            writer.write_mavlink(frame, direction=direction, log_time_ns=t)
            if i % _RATE_HZ == 0:
                writer.write("/camera/image", CompressedImage(images[i % 16]), log_time_ns=t)
                if i % (_RATE_HZ * 20) == 0 and path.stat().st_size >= size_mb * 1e6:
                    break
            i += 1
        return writer.message_count


def _median_s(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _cli(path: Path, *flags: str) -> None:
    subprocess.run(
        [sys.executable, "-m", "uavtool", "info", *flags, str(path)],
        check=True,
        stdout=subprocess.DEVNULL,
    )


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick", action="store_true", help="the smallest run: --size-mb 5 --repeat 2"
    )
    parser.add_argument("--size-mb", type=float, default=100.0, help="default: %(default)s")
    parser.add_argument("--repeat", type=int, default=5, help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(size_mb=5.0, repeat=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "big.mcap"
        t0 = time.perf_counter()
        messages = write_recording(path, args.size_mb)
        size_mb = path.stat().st_size / 1e6
        print(
            f"recording: {size_mb:.1f} MB, {messages} messages ({time.perf_counter() - t0:.1f} s)"
        )
        summarize(path)  # warm the page cache: both sides read from memory
        rows = [
            ("summarize, summary only", lambda: summarize(path, verify=False)),
            ("summarize, every chunk checked", lambda: summarize(path, verify=True)),
            ("uavtool info --no-verify", lambda: _cli(path, "--no-verify")),
            ("uavtool info (checks)", lambda: _cli(path)),
        ]
        results = [(name, _median_s(fn, args.repeat)) for name, fn in rows]
        for name, seconds in results:
            print(f"  {name:<32} {seconds * 1000:9.1f} ms")
        lib_ratio = results[1][1] / results[0][1]
        cli_ratio = results[3][1] / results[2][1]
        rate = size_mb / results[1][1]
        print(
            f"ratio with CRC checks / without: library {lib_ratio:.0f}x, command {cli_ratio:.1f}x"
        )
        print(f"checking runs at {rate:.0f} MB/s")


if __name__ == "__main__":
    main()
