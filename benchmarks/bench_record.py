"""`uavtool record`'s overhead per MAVLink message and per camera frame, against pymavlink's
`mavutil` telemetry-log writer (what MAVProxy's tlog is) on the very same stream, in one run.

    python benchmarks/bench_record.py [--quick]

The stream is the built-in vehicle's own telemetry (its message mix and rates: ~43 frames
per second, GLOBAL_POSITION_INT at 10 Hz), packed once. Per MAVLink message, ours is the
link tap the recorder installs (`PassiveRecorder.mavlink`: raw frame on /mavlink/raw plus
its decoded JSON view, zstd chunks, background fsync) and, once per GLOBAL_POSITION_INT, the
telemetry sample (/vehicle/telemetry, /vehicle/pose, /vehicle/fix); mavutil's is
`mavlogfile.write` of the 8-byte time stamp and the frame. Per camera frame (640x480 render
of the paper scene), ours is PNG encoding plus the image, calibration, pose and frame
record; the baseline is the PNG encoding plus writing it to a file, as a tlog user would
keep frames beside the log. Prints µs per item and the ratio ours / baseline.

``--quick``: 20 s of the stream and 20 frames (not 120 s and 100).
"""

from __future__ import annotations

import argparse
import itertools
import os
import struct
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MAVLINK20", "1")  # mavutil reads it at import: MAVLink 2 framing

from pymavlink import mavutil

from uavtool.camera import CameraPose, Intrinsics
from uavtool.geo import GeoPoint
from uavtool.images import png_encode
from uavtool.mission import Telemetry
from uavtool.recorder.frames import Frame
from uavtool.recorder.sink import PassiveRecorder
from uavtool.recording import RecordingWriter
from uavtool.sitl import Sitl, SitlConfig
from uavtool.world import load_scene, render


def vehicle_stream(seconds: float) -> list[bytes]:
    """Every frame the built-in vehicle sends a ground station in ``seconds`` of sim time."""
    frames: list[bytes] = []
    sitl = Sitl(SitlConfig(endpoints=()))
    link = sitl.attach("bench", frames.append)
    sitl.deliver(link, link.encoder.heartbeat_encode(6, 8, 0, 0, 0).pack(link.encoder))
    for _ in range(int(seconds * 50)):
        sitl.step()
    sitl.close()
    return frames


def bench_messages(frames: list[bytes], tmp: Path) -> tuple[float, float]:
    t0_ns = 1_700_000_000_000_000_000
    times = [t0_ns + i * 400_000 for i in range(len(frames))]  # ~2.5 kHz, as from a fast link
    # mavutil's tlog writer
    start = time.perf_counter()
    log = mavutil.mavlogfile(str(tmp / "stream.tlog"), write=True)
    for t, frame in zip(times, frames, strict=True):
        log.write(struct.pack(">Q", t // 1000) + frame)
    log.close()
    baseline = time.perf_counter() - start
    # ours
    clock = itertools.count(t0_ns, 400_000)
    telemetry = Telemetry(
        0, (1.0, 2.0, 20.0), (0.0, 0.0, 0.0), 90.0, "AUTO", True, False, -90.0, 0.0, 90
    )
    start = time.perf_counter()
    with RecordingWriter(tmp / "stream.mcap") as writer:
        recorder = PassiveRecorder(
            writer, clock_ns=lambda: next(clock), origin=GeoPoint(50, 19, 200)
        )
        for frame in frames:
            recorder.mavlink("in", frame)
            if frame[7] == 33 and frame[8] == 0 and frame[9] == 0:  # GLOBAL_POSITION_INT
                recorder.telemetry(telemetry)
    ours = time.perf_counter() - start
    return baseline / len(frames), ours / len(frames)


def bench_frames(n: int, tmp: Path) -> tuple[float, float]:
    scene = load_scene("paper")
    intrinsics = Intrinsics.from_hfov()
    images = [
        render(scene, CameraPose((i * 0.5, 0.0, 40.0), 0.0, -90.0), intrinsics) for i in range(n)
    ]
    start = time.perf_counter()
    for i, image in enumerate(images):
        (tmp / f"frame_{i:04d}.png").write_bytes(png_encode(image))
    baseline = time.perf_counter() - start
    t = iter(range(1_700_000_000_000_000_000, 1 << 62, 100_000_000))
    start = time.perf_counter()
    with RecordingWriter(tmp / "frames.mcap") as writer:
        recorder = PassiveRecorder(writer, clock_ns=lambda: next(t), origin=GeoPoint(50, 19, 200))
        for i, image in enumerate(images):
            pose = CameraPose((i * 0.5, 0.0, 40.0), 0.0, -90.0)
            recorder.frame(Frame(i, png_encode(image), intrinsics, i * 100, pose, i * 100, -1, ""))
    ours = time.perf_counter() - start
    return baseline / n, ours / n


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick", action="store_true", help="20 s of the stream and 20 frames (not 120 s, 100)"
    )
    args = parser.parse_args()
    seconds, n_frames = (20.0, 20) if args.quick else (120.0, 100)
    frames = vehicle_stream(seconds)
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        base_msg, ours_msg = bench_messages(frames, tmp)
        base_img, ours_img = bench_frames(n_frames, tmp)
    print(f"stream: {len(frames)} MAVLink frames ({seconds:g} s of the built-in vehicle)")
    print(
        f"per MAVLink message: mavutil tlog {base_msg * 1e6:7.1f} µs, "
        f"uavtool record {ours_msg * 1e6:7.1f} µs  (ratio {ours_msg / base_msg:.1f}x)"
    )
    print(
        f"per camera frame:    PNG to a file {base_img * 1e3:6.2f} ms, "
        f"uavtool record {ours_img * 1e3:6.2f} ms  (ratio {ours_img / base_img:.2f}x)"
    )
    rate = 1.0 / ours_msg
    print(f"uavtool record keeps up with {rate:,.0f} MAVLink messages/s on one core")


if __name__ == "__main__":
    main()
