"""A real writer process killed with SIGKILL loses at most about one second of data."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from uavtool.recording import RecordingReader, summarize

_CHILD = """
import sys, time
from tests.recording.sample import mavlink_frames
from uavtool.recording import RecordingWriter
frames = mavlink_frames(50)
with RecordingWriter(sys.argv[1], chunk_interval_ns=1_000_000_000) as writer:
    i = 0
    while True:
        direction, frame = frames[i % 50]
        writer.write_mavlink(frame, direction=direction, log_time_ns=time.time_ns())
        if i == 0:
            print("writing", flush=True)
        i += 1
        time.sleep(0.002)
"""


def test_sigkill_loses_at_most_about_one_second(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    repo = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONPATH": str(repo)}
    child = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(path)], stdout=subprocess.PIPE, cwd=repo, env=env
    )
    try:
        assert child.stdout is not None
        assert child.stdout.readline() == b"writing\n"
        time.sleep(3.0)
        killed_at_ns = time.time_ns()
        child.send_signal(signal.SIGKILL)
    finally:
        child.wait(timeout=30)
        if child.stdout is not None:
            child.stdout.close()
    assert child.returncode == -signal.SIGKILL
    info = summarize(path)
    assert not info.whole
    with RecordingReader(path) as reader:
        last_ns = max(m.log_time_ns for m in reader.messages(["/mavlink/raw"]))
    lost_s = (killed_at_ns - last_ns) / 1e9
    # one chunk interval, plus scheduling slack on a loaded 2-core machine
    assert 0.0 <= lost_s <= 1.3, lost_s
