"""Recording throughput: uavtool's writer/reader against the bare `mcap` Writer/reader.

    python benchmarks/bench_recording.py [--quick]

Each case writes the very same file both ways (checked byte for byte): zstd chunks closed
after each second of log time, the same header and metadata. Our writer adds the lock, topic
checks, per-channel sequence numbers and, by default, an fsync of each closed chunk (on a
background thread). The bare Writer does not fsync, except in the row that fsyncs inline
after each chunk (what a writer without the background thread pays). Serialization
(json.dumps, Protobuf) is counted on both sides; in the MAVLink case only ours decodes the
frames. Prints MB/s of message data, messages/s and the ratio (goal: writer >= 0.8x of
bare, fsync on). ``--quick``: 20,000 messages and 300 frames, best of 3 (not 100,000, 1500,
best of 5).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from uavtool import __version__
from uavtool.recording import (
    CompressedImage,
    Direction,
    RecordingReader,
    RecordingWriter,
    foxglove,
    rawframe,
)
from uavtool.recording.schemas import DEFAULT_DIALECT, MavlinkDecoder, dumps, mavlink_schema
from uavtool.recording.writer import LIBRARY, TOOL_METADATA

T0 = 1_700_000_000_000_000_000
CHUNK_NS = 1_000_000_000  # RecordingWriter's default chunk interval


def _telemetry(n: int) -> list[dict[str, object]]:
    return [
        {
            "time_boot_ms": i * 2,
            "lat_deg": 47.3977 + i * 1e-7,
            "lon_deg": 8.5456,
            "alt_m": 45.0 + (i % 100) * 0.01,
            "vel_ned_mps": [1.0, -0.5, 0.0],
            "heading_deg": (i * 0.1) % 360.0,
            "mode": "GUIDED",
            "armed": True,
            "battery_pct": 87,
        }
        for i in range(n)
    ]


def _png_frames(n: int) -> list[bytes]:
    rng = np.random.default_rng(1)
    frames = []
    for i in range(n):
        img = np.full((480, 640, 3), (60, 120, 60), np.uint8)
        for _ in range(4):
            x, y = rng.integers(0, 560), rng.integers(0, 400)
            cv2.rectangle(img, (int(x), int(y)), (int(x) + 80, int(y) + 60), (i % 255, 40, 200), -1)
        ok, png = cv2.imencode(
            ".png",
            img,
            [cv2.IMWRITE_PNG_COMPRESSION, 1, cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_NONE],
        )
        assert ok
        frames.append(png.tobytes())
    return frames


def _mavlink(n: int) -> list[tuple[Direction, bytes]]:
    from pymavlink.dialects.v20 import ardupilotmega as m

    mav = m.MAVLink(None, srcSystem=1, srcComponent=1)
    return [
        (
            Direction.IN,
            bytes(
                m.MAVLink_global_position_int_message(
                    i, 473977420, 85455940, 500000, 45000, 1, 2, 3, 90
                ).pack(mav)
            ),
        )
        for i in range(n)
    ]


def _best(*fns: Callable[[], None], repeats: int) -> list[float]:
    """Fastest of ``repeats`` interleaved runs of each function: the machine is shared, and
    interleaving exposes every contender to the same background load. Each run starts with
    no dirty pages, so none pays for writing back the previous one's file."""
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, out in zip(fns, times, strict=True):
            os.sync()
            t = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t)
    return [min(t) for t in times]


def _row(label: str, seconds: float, n: int, nbytes: int, ref: float | None = None) -> None:
    ratio = f"  {ref / seconds:5.2f}x of bare" if ref else ""
    print(f"  {label:<34} {nbytes / seconds / 1e6:8.1f} MB/s {n / seconds:10.0f} msg/s{ratio}")


class _Bare:
    """The bare mcap `Writer` set up to write exactly what `RecordingWriter` writes: same
    header and first metadata record, zstd, and a chunk closed after each second of log time
    (mcap's own policy is size only, so the loop does what our writer does internally)."""

    def __init__(self, path: Path, *, fsync: bool = False) -> None:
        self._fsync = fsync  # inline, after each chunk: what our writer did before
        self._file = path.open("wb")
        self.w = Writer(
            self._file,
            chunk_size=1 << 62,
            compression=CompressionType.ZSTD,
            enable_data_crcs=True,  # as RecordingWriter: the data section's CRC
        )
        self.w.start(profile="", library=LIBRARY)
        tool = {"version": __version__, "dialect": DEFAULT_DIALECT, "mavlink": "2.0"}
        self.w.add_metadata(TOOL_METADATA, tool)
        self._start_ns: int | None = None

    def add(self, cid: int, t: int, data: bytes, seq: int) -> None:
        self.w.add_message(cid, log_time=t, data=data, publish_time=t, sequence=seq)
        if self._start_ns is None:
            self._start_ns = t
        elif t - self._start_ns >= CHUNK_NS:
            self.w.flush()
            if self._fsync:
                os.fsync(self._file.fileno())
            self._start_ns = None

    def finish(self) -> None:
        self.w.finish()
        self._file.flush()
        if self._fsync:
            os.fsync(self._file.fileno())
        self._file.close()


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="smaller inputs: 20,000 messages, 300 frames, best of 3 (not 100,000, 1500, 5)",
    )
    args = parser.parse_args()
    n_json, n_png, repeats = (20_000, 300, 3) if args.quick else (100_000, 1500, 5)
    with tempfile.TemporaryDirectory(prefix="bench_rec_") as tmp:
        _run(Path(tmp), n_json, n_png, repeats)


def _run(tmp: Path, n_json: int, n_png: int, repeats: int) -> None:
    telemetry, frames, mav = _telemetry(n_json), _png_frames(n_png), _mavlink(n_json)
    json_bytes = sum(len(dumps(d)) for d in telemetry)
    dt_json, dt_png = 2_000_000, 100_000_000  # 500 Hz telemetry, 10 Hz camera (log time)

    def bare_json(fsync: bool) -> Callable[[], None]:
        def run() -> None:
            bare = _Bare(tmp / "bare_json.mcap", fsync=fsync)
            sid = bare.w.register_schema("t.Telemetry", "jsonschema", b"{}")
            cid = bare.w.register_channel("/telemetry", "json", sid)
            for i, d in enumerate(telemetry):
                bare.add(cid, T0 + i * dt_json, dumps(d), i)
            bare.finish()

        return run

    def ours_json(fsync: bool) -> Callable[[], None]:
        def run() -> None:
            with RecordingWriter(tmp / "ours_json.mcap", fsync=fsync) as w:
                w.add_json_topic("/telemetry", schema_name="t.Telemetry", schema={})
                for i, d in enumerate(telemetry):
                    w.write_json("/telemetry", d, log_time_ns=T0 + i * dt_json)

        return run

    images = [foxglove.encode(CompressedImage(p), T0 + i * dt_png) for i, p in enumerate(frames)]
    png_bytes = sum(len(b) for b in images)

    def bare_png(fsync: bool) -> Callable[[], None]:
        def run() -> None:
            bare = _Bare(tmp / "bare_png.mcap", fsync=fsync)
            schema = foxglove.schema_data(CompressedImage)
            sid = bare.w.register_schema("foxglove.CompressedImage", "protobuf", schema)
            cid = bare.w.register_channel("/camera/image", "protobuf", sid)
            for i, p in enumerate(frames):
                t = T0 + i * dt_png
                bare.add(cid, t, foxglove.encode(CompressedImage(p), t), i)
            bare.finish()

        return run

    def ours_png(fsync: bool) -> Callable[[], None]:
        def run() -> None:
            with RecordingWriter(tmp / "ours_png.mcap", fsync=fsync) as w:
                for i, p in enumerate(frames):
                    w.write("/camera/image", CompressedImage(p), log_time_ns=T0 + i * dt_png)

        return run

    decoder = MavlinkDecoder()
    decoded = [decoder.decode(f) for _d, f in mav]
    mav_bytes = sum(len(f) for _d, f in mav)

    def bare_mav() -> None:  # the same two messages per frame, decoded beforehand
        bare = _Bare(tmp / "bare_mav.mcap")
        raw = dec = 0
        for i, ((d, frame), js) in enumerate(zip(mav, decoded, strict=True)):
            t = T0 + i * dt_json
            if not raw:
                sid = bare.w.register_schema(rawframe.SCHEMA_NAME, "protobuf", rawframe.SCHEMA_DATA)
                meta = {"dialect": DEFAULT_DIALECT}
                raw = bare.w.register_channel("/mavlink/raw", "protobuf", sid, meta)
            bare.add(raw, t, rawframe.encode(d, frame), i)
            assert js is not None
            if not dec:
                name, schema = mavlink_schema(DEFAULT_DIALECT, js[0])
                sid = bare.w.register_schema(name, "jsonschema", schema)
                dec = bare.w.register_channel(f"/mavlink/in/{js[1]}", "json", sid)
            bare.add(dec, t, dumps(js[2]), i)
        bare.finish()

    def ours_mav() -> None:
        with RecordingWriter(tmp / "ours_mav.mcap") as w:
            for i, (d, frame) in enumerate(mav):
                w.write_mavlink(frame, direction=d, log_time_ns=T0 + i * dt_json)

    print(f"writer: telemetry JSON, {n_json} dicts ({json_bytes / n_json:.0f} B), 500 Hz log time")
    fns = bare_json(False), bare_json(True), ours_json(True), ours_json(False)
    ref, c, a, b = _best(*fns, repeats=repeats)
    _same(tmp, "json")
    _row("bare mcap Writer (+json.dumps)", ref, n_json, json_bytes)
    _row("bare + inline fsync per chunk", c, n_json, json_bytes, ref)
    _row("RecordingWriter.write_json (fsync)", a, n_json, json_bytes, ref)
    _row("RecordingWriter.write_json fsync=False", b, n_json, json_bytes, ref)
    kib = png_bytes / n_png / 1024
    print(f"writer: PNG frames, {n_png} frames ({kib:.1f} KiB), 10 Hz log time")
    ref, c, a, b = _best(
        bare_png(False), bare_png(True), ours_png(True), ours_png(False), repeats=repeats
    )
    _same(tmp, "png")
    _row("bare mcap Writer (+Protobuf)", ref, n_png, png_bytes)
    _row("bare + inline fsync per chunk", c, n_png, png_bytes, ref)
    _row("RecordingWriter.write image (fsync)", a, n_png, png_bytes, ref)
    _row("RecordingWriter.write image fsync=False", b, n_png, png_bytes, ref)
    print(f"writer: MAVLink, {n_json} frames -> raw + decoded JSON (2 messages each)")
    ref, a = _best(bare_mav, ours_mav, repeats=repeats)
    _same(tmp, "mav")
    _row("bare mcap Writer (decoded beforehand)", ref, n_json, mav_bytes)
    _row("RecordingWriter.write_mavlink (decodes)", a, n_json, mav_bytes, ref)

    for name, n, nbytes in (("ours_json", n_json, json_bytes), ("ours_png", n_png, png_bytes)):
        path = tmp / f"{name}.mcap"

        def bare_read(path: Path = path) -> None:
            with path.open("rb") as f:
                for _ in make_reader(f).iter_messages(log_time_order=False):
                    pass

        def our_read(path: Path = path) -> None:
            with RecordingReader(path) as r:
                for _ in r.messages():
                    pass

        print(f"reader: {name.removeprefix('ours_')} recording, all messages")
        ref, a = _best(bare_read, our_read, repeats=repeats)
        _row("bare mcap reader (log_time_order=False)", ref, n, nbytes)
        _row("RecordingReader.messages", a, n, nbytes, ref)


def _same(tmp: Path, case: str) -> None:
    """Both writers must have written the very same file, or the comparison means nothing."""
    if (tmp / f"bare_{case}.mcap").read_bytes() != (tmp / f"ours_{case}.mcap").read_bytes():
        raise SystemExit(f"{case}: bare and RecordingWriter files differ")


if __name__ == "__main__":
    main()
