"""Background writes and fsync: failures surface as `RecordingError`, `close` waits for every
write and sync, a writer waits once a few chunks wait for the thread, and threads sharing a
writer lose or reorder nothing while chunks are written and synced behind them."""

from __future__ import annotations

import errno
import gc
import json
import os
import re
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.recording.sample import OBS_SCHEMA, T0_NS, write_sample
from uavtool.recording import RecordingError, RecordingReader, RecordingWriter
from uavtool.recording.encoder import MAGIC, Chunk, McapEncoder
from uavtool.recording.syncer import BACKLOG


def _eio(fd: int) -> None:
    raise OSError(errno.EIO, os.strerror(errno.EIO))


def _sync_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith("recording ")]


def _writer(path: Path, **kwargs: object) -> RecordingWriter:
    writer = RecordingWriter(path, chunk_interval_ns=10, **kwargs)  # type: ignore[arg-type]
    writer.add_json_topic("/obs", schema_name="t.Obs", schema=OBS_SCHEMA)
    return writer


def _write(writer: RecordingWriter, step: int) -> None:
    writer.write_json("/obs", {"step": step}, log_time_ns=T0_NS + 10 * step)


def _first_failure(writer: RecordingWriter, steps: int, pause_s: float) -> tuple[int, str]:
    """Write until a write raises `RecordingError`: ``(step, message)``."""
    for step in range(steps):
        try:
            _write(writer, step)
        except RecordingError as exc:
            return step, str(exc)
        time.sleep(pause_s)  # lets the sync thread run
    raise AssertionError(f"{steps} writes and no failure")


def test_a_failed_background_fsync_is_raised_by_later_writes_and_close(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(os, "fsync", _eio)
    path = tmp_path / "rec.mcap"
    writer = _writer(path)
    problem = r"rec\.mcap: cannot sync to disk: Input/output error"
    step, message = _first_failure(writer, 5000, 0.001)  # every write closes a chunk
    assert re.search(problem, message)
    with pytest.raises(RecordingError, match=problem):
        writer.add_metadata("outcome", {"result": "matched"})
    with pytest.raises(RecordingError, match=problem):
        writer.close()
    writer.close()  # idempotent once closed
    assert _sync_threads() == []
    with RecordingReader(path) as reader:  # no summary, but what was written is readable
        assert not reader.health.whole
        assert 0 < sum(1 for _ in reader.messages(["/obs"])) <= step


def test_flush_waits_for_the_disk_and_reports_a_failed_fsync(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    synced = threading.Event()

    def slow_fsync(fd: int) -> None:
        time.sleep(0.05)
        synced.set()

    monkeypatch.setattr(os, "fsync", slow_fsync)
    writer = RecordingWriter(tmp_path / "ok.mcap", chunk_interval_ns=10**12)
    writer.add_json_topic("/obs", schema_name="t.Obs", schema=OBS_SCHEMA)
    _write(writer, 0)
    writer.flush()
    assert synced.is_set()
    writer.close()
    monkeypatch.setattr(os, "fsync", _eio)
    writer = _writer(tmp_path / "bad.mcap")
    _write(writer, 0)
    with pytest.raises(RecordingError, match=r"bad\.mcap: cannot sync to disk"):
        writer.flush()
    with pytest.raises(RecordingError, match=r"bad\.mcap: cannot sync to disk"), writer:
        pass  # leaving the block closes the writer, which reports the failure again


def test_a_failed_write_is_a_recording_error(tmp_path: Path) -> None:
    pipe = tmp_path / "pipe.mcap"
    os.mkfifo(pipe)
    head = bytearray()

    def reader() -> None:  # reads the start, then goes away like a lost disk
        with pipe.open("rb", buffering=0) as f:
            head.extend(f.read(8))

    thread = threading.Thread(target=reader)
    thread.start()
    writer = _writer(pipe, fsync=False)
    thread.join()
    assert bytes(head) == MAGIC
    _step, message = _first_failure(writer, 100, 0.0)
    assert re.search(r"pipe\.mcap: cannot write: Broken pipe", message)
    with pytest.raises(RecordingError, match="Broken pipe"):
        _write(writer, 100)
    with pytest.raises(RecordingError, match="Broken pipe"):
        writer.close()


def test_a_full_disk_at_open_is_a_recording_error() -> None:
    with pytest.raises(RecordingError, match="/dev/full: cannot write: No space left"):
        RecordingWriter("/dev/full")
    assert _sync_threads() == []


def test_close_waits_for_every_fsync_and_the_last_covers_the_whole_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_fsync: Callable[[int], None] = os.fsync
    started: list[int] = []  # file size when each fsync began
    finished: list[int] = []

    def slow_fsync(fd: int) -> None:
        started.append(os.fstat(fd).st_size)
        time.sleep(0.02)
        real_fsync(fd)
        finished.append(started[-1])

    monkeypatch.setattr(os, "fsync", slow_fsync)
    path = tmp_path / "rec.mcap"
    writer = _writer(path)
    for step in range(40):  # 40 chunks, written much faster than one fsync takes
        _write(writer, step)
    writer.close()
    assert finished == started  # none still running when close returned
    assert finished[-1] == path.stat().st_size  # the last one saw the summary and footer
    assert len(finished) < 20  # requests made during a sync were served together
    assert _sync_threads() == []
    with RecordingReader(path) as reader:
        assert reader.health.whole
        assert [json.loads(m.data)["step"] for m in reader.messages()] == list(range(40))
    # nothing left for the sync thread when close writes the summary: close syncs it itself
    started.clear()
    finished.clear()
    writer = _writer(tmp_path / "quiet.mcap")
    _write(writer, 0)
    writer.flush()
    assert finished == [(tmp_path / "quiet.mcap").stat().st_size]
    writer.add_metadata("outcome", {"result": "matched"})
    writer.close()
    assert finished[-1] == (tmp_path / "quiet.mcap").stat().st_size


def test_threads_keep_order_and_count_while_chunks_sync_behind_them(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    n_threads, n = 4, 300
    with RecordingWriter(path, chunk_interval_ns=2_000) as writer:
        for j in range(n_threads):
            writer.add_json_topic(f"/t{j}", schema_name="t.Obs", schema=OBS_SCHEMA)
        writer.add_json_topic("/shared", schema_name="t.Obs", schema=OBS_SCHEMA)
        start = threading.Barrier(n_threads)

        def work(j: int) -> None:
            start.wait()
            for i in range(n):
                t = T0_NS + 1_000 * i + j
                writer.write_json(f"/t{j}", {"step": i}, log_time_ns=t)
                writer.write_json("/shared", {"step": i, "alt_m": float(j)}, log_time_ns=t)

        threads = [threading.Thread(target=work, args=(j,)) for j in range(n_threads)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    with RecordingReader(path) as reader:
        assert reader.health.whole
        for j in range(n_threads):
            messages = list(reader.messages([f"/t{j}"]))
            assert [json.loads(m.data)["step"] for m in messages] == list(range(n))
            assert [m.sequence for m in messages] == list(range(n))
        shared = list(reader.messages(["/shared"]))
    assert [m.sequence for m in shared] == list(range(n_threads * n))
    for j in range(n_threads):
        steps = [json.loads(m.data)["step"] for m in shared if json.loads(m.data)["alt_m"] == j]
        assert steps == list(range(n))
    assert writer.message_count == 2 * n_threads * n


def test_background_fsync_does_not_change_the_bytes(tmp_path: Path) -> None:
    write_sample(tmp_path / "a.mcap", seconds=1.0, fsync=True)
    write_sample(tmp_path / "b.mcap", seconds=1.0, fsync=False)
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


# Python rightly warns about the file the dropped writer leaves unclosed.
@pytest.mark.filterwarnings("ignore::ResourceWarning")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_writer_dropped_without_close_ends_its_sync_thread(tmp_path: Path) -> None:
    def sync_threads() -> list[threading.Thread]:
        return [t for t in threading.enumerate() if t.name == "recording dropped.mcap"]

    writer = _writer(tmp_path / "dropped.mcap")
    _write(writer, 0)
    _write(writer, 1)  # closes a chunk: a sync request
    writer.flush()  # served: the thread now waits for the next request
    threads = sync_threads()
    assert len(threads) == 1 and threads[0].is_alive()
    del writer
    gc.collect()
    threads[0].join(timeout=5.0)
    assert not threads[0].is_alive()


def test_a_failed_background_chunk_write_is_raised_by_later_writes_and_close(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(self: McapEncoder, chunk: object) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(McapEncoder, "write_chunk", full)
    writer = _writer(tmp_path / "full.mcap")
    problem = r"full\.mcap: cannot write: No space left on device"
    _step, message = _first_failure(writer, 5000, 0.001)
    assert re.search(problem, message)
    with pytest.raises(RecordingError, match=problem):
        writer.close()
    assert _sync_threads() == []


def test_a_writer_waits_once_backlog_chunks_wait_for_the_thread(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A writer that holds the GIL can starve the thread: past `BACKLOG` waiting chunks the
    writer waits, so a crash never loses more than those."""
    release = threading.Event()
    real_write = McapEncoder.write_chunk

    def stuck(self: McapEncoder, chunk: Chunk) -> None:
        release.wait(10.0)
        real_write(self, chunk)

    monkeypatch.setattr(McapEncoder, "write_chunk", stuck)
    writer = _writer(tmp_path / "slow.mcap")
    steps = 2 * BACKLOG + 6  # every second write closes a chunk (10 ns of log time)
    done: list[int] = []

    def produce() -> None:
        for step in range(steps):
            _write(writer, step)
            done.append(step)

    producer = threading.Thread(target=produce)
    producer.start()
    try:
        time.sleep(0.3)
        # the first chunk being written, BACKLOG more waiting: the next close (step
        # 2 * BACKLOG + 3) waits
        assert len(done) == 2 * BACKLOG + 3
    finally:
        release.set()
        producer.join()
        writer.close()
    with RecordingReader(tmp_path / "slow.mcap") as reader:
        assert reader.health.whole
        assert [json.loads(m.data)["step"] for m in reader.messages()] == list(range(steps))
