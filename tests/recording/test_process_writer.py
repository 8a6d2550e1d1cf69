"""`ProcessWriter`: the same file as `RecordingWriter`, errors where they were, and a crash of
the flight's process loses only the batch it had not sent."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.recording.sample import OBS_SCHEMA, T0_NS, mavlink_frames, other_values
from uavtool.geo import GeoPoint
from uavtool.glb import mesh_glb
from uavtool.images import png_decode, png_encode
from uavtool.recording import (
    CompressedImage,
    Direction,
    Model3D,
    ProcessWriter,
    RecordingError,
    RecordingReader,
    RecordingWriter,
    RgbImage,
    TriangleMesh,
    cores,
    process,
    process_child,
    summarize,
)
from uavtool.recording.process import BATCH_NS

HOME = GeoPoint(47.397742, 8.545594, 488.0)


def _write(writer: Any, seconds: float = 6.0, rate_hz: int = 400) -> None:
    """Every kind of call, as a flight makes them, over ``seconds`` of log time."""
    frames = mavlink_frames(int(seconds * rate_hz))
    step_ns = 1_000_000_000 // rate_hz
    writer.add_json_topic("/mission/observations", schema_name="test.Obs", schema=OBS_SCHEMA)
    for i, (direction, frame) in enumerate(frames):
        t = T0_NS + i * step_ns
        writer.write_mavlink(frame, direction=direction, log_time_ns=t)
        if i % 40 == 0:
            writer.write_vehicle(
                (1.0 * i, -2.0, 45.0), 10.0 + i, HOME if i else None, log_time_ns=t
            )
            writer.write_json("/mission/observations", {"step": i, "alt_m": 45.5}, log_time_ns=t)
            writer.write_json_bytes(
                "/mission/observations", b'{"step":-1}', log_time_ns=t, publish_time_ns=t + 1
            )
        if i % rate_hz == 0:
            for topic, value in other_values():
                writer.write(topic, value, log_time_ns=t)
            writer.write_mavlink(frame, direction=Direction.IN, log_time_ns=t, publish_time_ns=5)
            writer.write_mavlink(b"\xfd\x01junk", direction=Direction.OUT, log_time_ns=t)
        if i == len(frames) // 2:
            writer.add_metadata("halfway", {"i": str(i)})
    writer.add_metadata("outcome", {"status": "completed"})


def test_the_file_is_the_one_recording_writer_writes(tmp_path: Path) -> None:
    metadata = {"mission": {"target": "red"}, "seeds": {"world": "7"}}
    with RecordingWriter(tmp_path / "inline.mcap", metadata=metadata, fsync=False) as inline:
        _write(inline)
    with ProcessWriter(tmp_path / "process.mcap", metadata=metadata, fsync=False) as process:
        _write(process)
    assert process.message_count == inline.message_count > 0
    assert (tmp_path / "process.mcap").read_bytes() == (tmp_path / "inline.mcap").read_bytes()


def test_misuse_raises_at_the_call(tmp_path: Path) -> None:
    with ProcessWriter(tmp_path / "a.mcap", fsync=False) as writer:
        frame = mavlink_frames(1)[0][1]
        with pytest.raises(ValueError, match="log_time_ns"):
            writer.write_mavlink(frame, direction=Direction.IN, log_time_ns=0)
        with pytest.raises(ValueError, match="log_time_ns"):
            writer.write_mavlink(frame, direction=Direction.IN, log_time_ns=1 << 64)
        with pytest.raises(ValueError, match="not a JSON topic"):
            writer.write_json_bytes("/nope", b"{}", log_time_ns=T0_NS)
        writer.add_json_topic("/j", schema_name="test.J", schema={"type": "object"})
        with pytest.raises(ValueError, match="not JSON"):
            writer.write_json("/j", {"x": float("nan")}, log_time_ns=T0_NS)
        with pytest.raises(ValueError, match="already carries"):
            writer.add_json_topic("/j", schema_name="test.K", schema={"type": "object"})
        topic, value = other_values()[0]
        writer.write(topic, value, log_time_ns=T0_NS)
        with pytest.raises(ValueError, match="carries"):
            writer.write(topic, other_values()[1][1], log_time_ns=T0_NS)  # type: ignore[arg-type]
        with pytest.raises(ValueError, match="reserved"):
            writer.add_metadata("uavtool", {})
    with pytest.raises(ValueError, match="closed"):
        writer.write_mavlink(frame, direction=Direction.IN, log_time_ns=T0_NS)
    with pytest.raises(ValueError, match="dialect"):
        ProcessWriter(tmp_path / "b.mcap", dialect="no_such_dialect")
    assert not (tmp_path / "b.mcap").exists()


def test_a_path_that_cannot_be_created_fails_at_once(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match=r"missing/a\.mcap: cannot create"):
        ProcessWriter(tmp_path / "missing" / "a.mcap")


def test_a_full_disk_is_a_recording_error_at_a_later_call_and_at_close() -> None:
    writer = ProcessWriter("/dev/full", fsync=False)
    frames = mavlink_frames(50)
    with pytest.raises(RecordingError, match="/dev/full: cannot write: No space left") as failed:
        _until_it_fails(writer, frames)
    with pytest.raises(RecordingError) as again:
        writer.write_mavlink(frames[0][1], direction=Direction.IN, log_time_ns=T0_NS)
    assert again.value is failed.value
    with pytest.raises(RecordingError, match="No space left"):
        writer.close()


def test_a_writer_process_that_dies_is_a_recording_error(tmp_path: Path) -> None:
    writer = ProcessWriter(tmp_path / "a.mcap", fsync=False)
    os.kill(writer._proc.pid, signal.SIGKILL)
    writer._proc.wait()
    frame = mavlink_frames(1)[0][1]
    with pytest.raises(RecordingError, match=r"writer process ended unexpectedly \(exit code -9\)"):
        _until_it_fails(writer, [(Direction.IN, frame)])
    with pytest.raises(RecordingError, match="ended unexpectedly"):
        writer.close()


def _until_it_fails(writer: ProcessWriter, frames: list[tuple[Direction, bytes]]) -> None:
    """Write frames, 0.1 s of log time apart (a batch each), until a write raises. The
    child's failure is heard at a later send: how much later depends on how long the child
    takes to start (its reader holds up to `BACKLOG_BYTES`), so the bound is wall time, not
    a count of frames (a loaded machine once took more than 100,000)."""
    deadline = time.monotonic() + 60
    i = 0
    while time.monotonic() < deadline:
        direction, frame = frames[i % len(frames)]
        writer.write_mavlink(frame, direction=direction, log_time_ns=T0_NS + i * 10**8)
        i += 1


_FLIGHT = """
import sys, time
from tests.recording.sample import mavlink_frames
from uavtool.recording import ProcessWriter
frames = mavlink_frames(50)
writer = ProcessWriter(sys.argv[1])
print(writer._proc.pid, flush=True)
i = 0
while True:
    direction, frame = frames[i % 50]
    writer.write_mavlink(frame, direction=direction, log_time_ns=time.time_ns())
    i += 1
    time.sleep(0.002)
"""


def test_a_killed_flight_loses_only_the_batch_it_had_not_sent(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    repo = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONPATH": str(repo)}
    flight = subprocess.Popen(
        [sys.executable, "-c", _FLIGHT, str(path)], stdout=subprocess.PIPE, cwd=repo, env=env
    )
    try:
        assert flight.stdout is not None
        child = int(flight.stdout.readline())
        time.sleep(2.5)
        killed_at_ns = time.time_ns()
        flight.send_signal(signal.SIGKILL)
    finally:
        flight.wait(timeout=30)
        if flight.stdout is not None:
            flight.stdout.close()
    deadline = time.monotonic() + 30
    while _alive(child) and time.monotonic() < deadline:  # it writes what it was sent
        time.sleep(0.05)
    assert not _alive(child)
    info = summarize(path)
    assert not info.whole
    with RecordingReader(path) as reader:
        last_ns = max(m.log_time_ns for m in reader.messages(["/mavlink/raw"]))
    lost_s = (killed_at_ns - last_ns) / 1e9
    assert 0.0 <= lost_s <= BATCH_NS / 1e9 + 0.3, lost_s  # plus scheduling slack


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie (its parent, the killed flight, is gone: init reaps it) counts as ended
    state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    return state != "Z"


_CUBE = TriangleMesh(
    tuple((float(x), float(y), float(z)) for x in (0, 1) for y in (0, 1) for z in (0, 1)),
    (
        (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
        (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),
    ),
)  # fmt: skip


@pytest.mark.parametrize("kind", [RecordingWriter, ProcessWriter])
def test_a_model_given_as_a_mesh_is_written_as_its_glb(tmp_path: Path, kind: Any) -> None:
    """A writer process makes the GLB of a model given as a mesh (the flight's process never
    imports trimesh): the file holds what the model's GLB bytes would have written."""
    as_mesh, as_glb = tmp_path / "mesh.mcap", tmp_path / "glb.mcap"
    with kind(as_mesh, fsync=False) as writer:
        writer.write("/mission/model", Model3D(b"", mesh=_CUBE), log_time_ns=T0_NS)
    glb = mesh_glb(_CUBE.vertices_m, _CUBE.faces)
    with RecordingWriter(as_glb, fsync=False) as writer:
        writer.write("/mission/model", Model3D(glb), log_time_ns=T0_NS)
    assert as_mesh.read_bytes() == as_glb.read_bytes()
    with RecordingReader(as_mesh) as reader:
        (entry,) = reader.entries(["/mission/model"])
    assert entry.value == Model3D(glb)
    assert glb[:4] == b"glTF" and len(glb) > 12 * 3 * 24  # 36 vertices, each with a normal


@pytest.mark.parametrize("kind", [RecordingWriter, ProcessWriter])
def test_a_raw_frame_is_written_as_its_png(tmp_path: Path, kind: Any) -> None:
    """A writer process encodes a raw frame's PNG (the flight's process does not): the file
    holds what the frame's PNG bytes would have written."""
    rng = np.random.default_rng(7)
    rgb = rng.integers(0, 256, size=(48, 64, 3), dtype=np.uint8)
    raw = RgbImage(rgb.tobytes(), 48, 64)
    as_raw, as_png = tmp_path / "raw.mcap", tmp_path / "png.mcap"
    with kind(as_raw, fsync=False) as writer:
        writer.write("/camera/image", CompressedImage(b"", raw=raw), log_time_ns=T0_NS)
    with RecordingWriter(as_png, fsync=False) as writer:
        writer.write("/camera/image", CompressedImage(png_encode(rgb)), log_time_ns=T0_NS)
    assert as_raw.read_bytes() == as_png.read_bytes()
    with RecordingReader(as_raw) as reader:
        (entry,) = reader.entries(["/camera/image"])
    assert np.array_equal(png_decode(entry.value.data), rgb)


def test_the_child_drains_the_pipe_while_its_writer_is_busy(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Batches are read ahead of the writer, up to `BACKLOG_BYTES`: a photo the child is
    compressing does not keep the flight waiting on a full pipe, and a flight that outruns
    the writer by more does wait."""
    monkeypatch.setattr(process_child, "BACKLOG_BYTES", 4 << 20)
    read, write = os.pipe()
    wake, wake_write = os.pipe()
    try:
        backlog = process_child._Backlog(read, wake)
        photo = bytes(range(256)) * 4096  # 1 MiB, as big as the pipe
        sent: list[int] = []

        def send() -> None:
            for i in range(8):
                os.write(write, b"".join(process._framed([(i, photo)])))
                sent.append(i)

        sender = threading.Thread(target=send, daemon=True)
        sender.start()
        deadline = time.monotonic() + 10
        while len(sent) < 4 and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.2)
        # nobody has taken a batch: four are held, the fifth waits for room, the pipe fills
        assert 4 <= len(sent) < 8
        for i in range(8):
            batch = backlog.next()
            assert batch is not None
            assert batch[0][0] == i
            assert batch[0][1] == photo
        sender.join(10)
        assert sent == list(range(8))
    finally:
        os.close(write)
    assert backlog.next() is None  # the pipe's end
    for fd in (read, wake, wake_write):
        os.close(fd)


def test_a_flush_wakes_the_child_at_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The child's reader sleeps between looks at an empty pipe (`POLL_S`); what the flight
    waits for (a flush, a close) is sent with a word on the wake pipe, which ends the sleep:
    with a sleep of a minute, the batch is still read in well under one."""
    monkeypatch.setattr(process_child, "POLL_S", (60.0, 60.0))
    read, write = os.pipe()
    wake, wake_write = os.pipe()
    os.set_blocking(read, False)
    os.set_blocking(wake, False)
    got: list[object] = []
    reader = threading.Thread(
        target=lambda: got.append(process_child._read_framed(read, wake)[0]), daemon=True
    )
    try:
        reader.start()
        time.sleep(0.2)  # the reader found the pipe empty and sleeps
        os.write(write, b"".join(process._framed(("flush",))))
        os.write(wake_write, b"w")
        reader.join(20)
        assert got == [("flush",)]
    finally:
        for fd in (read, write, wake, wake_write):
            os.close(fd)


@pytest.mark.parametrize(
    ("others_busy_cores", "span_s", "load", "spare"),
    [
        (0.1, 0.2, 9.0, True),  # others idle now: a load average a minute old does not count
        (1.0, 0.2, 0.0, False),  # another process keeps a core busy
        (0.4, 0.2, 9.0, True),
        (0.6, 0.2, 0.0, False),
        (0.0, 60.0, 1.9, False),  # the window too old: the load average decides
        (0.0, 60.0, 0.3, True),
        (0.0, 0.001, 1.9, False),  # too short to tell
    ],
)
def test_a_writer_process_is_chosen_when_other_processes_leave_a_core(
    monkeypatch: pytest.MonkeyPatch,
    others_busy_cores: float,
    span_s: float,
    load: float,
    spare: bool,
) -> None:
    """The flight takes a core; the writer is given one only when others leave half of the
    other core free, measured since the last call (the load average when that is too old)."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda _pid: {0, 1})
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr(os, "getloadavg", lambda: (load, load, load))
    mine_s = 0.9 * span_s  # this process: busy most of the window (its start-up)
    monkeypatch.setattr(cores, "_last_sample", (100.0, 50.0, 3.0))
    now = (100.0 + span_s, 50.0 + mine_s + others_busy_cores * span_s, 3.0 + mine_s)
    monkeypatch.setattr(cores, "_cpu_sample", lambda: now)
    assert cores.core_to_spare() is spare
    assert cores._last_sample == now  # the next call measures from here


def test_one_core_never_gets_a_writer_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(os, "sched_getaffinity", lambda _pid: {0})
    assert cores.core_to_spare() is False


def test_the_flight_knows_every_value_the_writer_encodes() -> None:
    """`FOXGLOVE_TYPES` (the flight's process checks values by it, without Protobuf) is what
    the Foxglove encoder encodes: a value added to one is added to the other."""
    from uavtool.recording.foxglove import _PB_CLASS
    from uavtool.recording.values import FOXGLOVE_TYPES

    assert set(_PB_CLASS) == FOXGLOVE_TYPES
