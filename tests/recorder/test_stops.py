"""How a recording ends: a silent vehicle (no file, exit 2), SIGKILL (≤ about 1 s lost, the
file recovers), a ground station that is not ours flying (MAVSDK), a camera that is a video
file (OpenCV)."""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner

from tests.recorder.flight import free_udp_port, vehicle
from tests.sitl.client import Client
from uavtool.cli import cli
from uavtool.images import png_decode
from uavtool.recorder import RecordConfig, Stop, record
from uavtool.recording import CompressedImage, JsonDocument, RecordingReader, recover, summarize
from uavtool.recording.topics import FRAMES, IMAGE, TELEMETRY
from uavtool.world import load_scene

REPO = Path(__file__).resolve().parents[2]


def test_a_vehicle_that_never_answers_is_one_line_and_exit_2(tmp_path: Path) -> None:
    out = tmp_path / "none.mcap"
    port = free_udp_port()
    args = ["record", "--connect", f"udpin:127.0.0.1:{port}", "-o", str(out), "--timeout", "1"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2
    message = result.output.strip()
    assert message.count("\n") == 0 or "Traceback" not in message
    assert f"udpin:127.0.0.1:{port}: no heartbeat from a vehicle in 1 s" in message
    assert "nothing was sent (passive)" in message
    assert list(tmp_path.iterdir()) == []


def test_sigkill_loses_at_most_about_one_second_and_the_file_recovers(tmp_path: Path) -> None:
    out = tmp_path / "killed.mcap"
    scene = load_scene("paper")
    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0",)) as sitl:
        args = ["--connect", f"tcp:127.0.0.1:{sitl.ports[0]}", "-o", str(out)]
        proc = subprocess.Popen(
            [sys.executable, "-m", "uavtool", "record", *args, "--camera", "sim", "--rate", "2"],
            cwd=REPO,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stderr is not None
            while "recording to" not in (line := proc.stderr.readline()):
                assert line, "record exited early"
            time.sleep(3.0)
            killed_at_ns = time.time_ns()
            os.kill(proc.pid, signal.SIGKILL)
        finally:
            proc.wait(timeout=30)
            assert proc.stderr is not None
            proc.stderr.close()
    partial = tmp_path / f"killed.mcap.{proc.pid}.partial"
    assert not out.exists() and partial.exists()  # as `fly`: the name appears only when whole
    assert not summarize(partial).whole
    with RecordingReader(partial) as reader:
        last_ns = max(m.log_time_ns for m in reader.messages([TELEMETRY]))
        assert sum(1 for _ in reader.messages([IMAGE])) >= 4
    assert 0.0 <= (killed_at_ns - last_ns) / 1e9 <= 1.3
    fixed = tmp_path / "fixed.mcap"
    result = recover(partial, fixed)
    assert result.messages > 0 and summarize(fixed).whole


def test_mavsdk_flies_while_record_records(tmp_path: Path) -> None:
    mavsdk = pytest.importorskip("mavsdk")
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.telemetry import Telemetry

    scene = load_scene("paper")
    out = tmp_path / "mavsdk.mcap"
    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0", "tcpin:127.0.0.1:0")) as sitl:
        summary: list[Any] = []
        config = RecordConfig(
            connect=f"tcp:127.0.0.1:{sitl.ports[1]}",
            output=out,
            camera="sim",
            rate_hz=2.0,
            until_landed=True,
            duration_s=90.0,
        )
        thread = threading.Thread(target=lambda: summary.append(record(config)))
        thread.start()
        sdk = mavsdk.Mavsdk(
            mavsdk.Configuration.create_with_component_type(mavsdk.ComponentType.GROUND_STATION)
        )
        try:
            sdk.add_any_connection(f"tcpout://127.0.0.1:{sitl.ports[0]}")
            system = sdk.first_autopilot(10.0)
            assert system is not None
            telemetry, action = Telemetry(system), Action(system)
            _until(lambda: telemetry.health().is_armable, "armable")
            action.set_takeoff_altitude(8.0)
            action.arm()
            action.takeoff()
            _until(lambda: telemetry.position().relative_altitude_m > 7.7, "8 m")
            action.land()
            thread.join(timeout=60)
        finally:
            sdk.destroy()
    assert summary and summary[0].stop is Stop.LANDED
    assert summary[0].messages_out == 0  # passive
    with RecordingReader(out) as reader:
        alts = [
            e.value.payload["pos_enu_m"][2]
            for e in reader.entries([TELEMETRY])
            if isinstance(e.value, JsonDocument)
        ]
    assert max(alts) == pytest.approx(8.0, abs=0.4) and alts[-1] < 0.1
    assert summary[0].frames >= 4


def test_direct_mode_asks_for_streams_but_keeps_quiet_beside_another_ground_station(
    tmp_path: Path,
) -> None:
    scene = load_scene("paper")
    port = free_udp_port()
    with vehicle(scene, endpoints=(f"udpout:127.0.0.1:{port}",)) as sitl:
        config = RecordConfig(
            connect=f"udpin:127.0.0.1:{port}",
            output=tmp_path / "alone.mcap",
            direct=True,
            duration_s=3.0,
        )
        alone = record(config)
        assert alone.messages_out > 0  # heartbeats and SET_MESSAGE_INTERVAL
        assert sitl.error is None
    port = free_udp_port()
    with vehicle(scene, endpoints=(f"udpout:127.0.0.1:{port}",)):
        gcs = Client(socket.socket(socket.AF_INET, socket.SOCK_DGRAM), udp_addr=("127.0.0.1", port))
        stop = threading.Event()

        def ground_station() -> None:  # a router forwards its heartbeat to us
            while not stop.wait(0.3):
                gcs.heartbeat()

        beat = threading.Thread(target=ground_station)
        beat.start()
        try:
            config = RecordConfig(
                connect=f"udpin:127.0.0.1:{port}",
                output=tmp_path / "beside.mcap",
                direct=True,
                duration_s=3.0,
            )
            beside = record(config)
        finally:
            stop.set()
            beat.join()
            gcs.close()
    assert beside.messages_out == 0


def test_an_opencv_camera_reads_a_video_file(tmp_path: Path) -> None:
    cv2 = pytest.importorskip("cv2")
    video = tmp_path / "camera.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 120))
    for i in range(40):
        frame = np.zeros((120, 160, 3), np.uint8)
        frame[:, : 4 * i] = (0, 0, 255)  # BGR red, growing left to right frame by frame
        writer.write(frame)
    writer.release()
    out = tmp_path / "video.mcap"
    scene = load_scene("paper")
    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0",)) as sitl:
        config = RecordConfig(
            connect=f"tcp:127.0.0.1:{sitl.ports[0]}",
            output=out,
            camera=f"file://{video}",
            rate_hz=5.0,
            duration_s=3.0,
        )
        summary = record(config)
    assert summary.frames >= 10
    with RecordingReader(out) as reader:
        images = [
            e.value.data for e in reader.entries([IMAGE]) if isinstance(e.value, CompressedImage)
        ]
        frames = [
            e.value.payload for e in reader.entries([FRAMES]) if isinstance(e.value, JsonDocument)
        ]
    first, later = png_decode(images[0], where="0"), png_decode(images[5], where="5")
    assert first.shape == (120, 160, 3)
    assert (later[:, :, 0] > 128).sum() > (first[:, :, 0] > 128).sum()  # the video advances
    for f in frames:  # each frame's pose: the telemetry sample nearest its capture
        assert abs(f["pose_dt_ms"]) <= 100 + 60  # half a period, at 8x speed-up, plus jitter
        assert math.isfinite(f["pose"]["heading_deg"])


def _until(check: Any, what: str, timeout: float = 30.0) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if check():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def test_until_landed_stops_when_the_vehicle_dies(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from uavtool.recorder import session

    monkeypatch.setattr(session, "LOST_S", 2.0, raising=False)  # 10 s by default
    out = tmp_path / "lost.mcap"
    port = free_udp_port()  # over UDP a dead vehicle is only silence
    sitl = vehicle(load_scene("paper"), endpoints=(f"udpout:127.0.0.1:{port}",)).start()
    config = RecordConfig(connect=f"udpin:127.0.0.1:{port}", output=out, until_landed=True)
    summary: list[Any] = []
    give_up = threading.Event()
    thread = threading.Thread(
        target=lambda: summary.append(record(config, stop_requested=give_up.is_set))
    )
    thread.start()
    try:
        _until(out.with_name(f"{out.name}.{os.getpid()}.partial").exists, "recording")
        time.sleep(1.0)
        sitl.stop()  # the vehicle dies in the air or on the ground: it will never land
        died = time.monotonic()
        thread.join(timeout=15)
        took = time.monotonic() - died
    finally:
        give_up.set()  # it recorded for ever
        thread.join()
        sitl.stop()
    assert summary[0].stop.value == "vehicle lost"
    # from the last message heard (just before it died) to the stop: about the 2 s limit
    assert 1.8 <= took < 5.0
    assert summarize(out).record_result["stopped"] == "vehicle lost"  # what info shows


def test_a_full_disk_names_the_file_that_keeps_the_recording(tmp_path: Path) -> None:
    """A write the OS refuses (here a file-size limit, as a full disk would) is one line that
    names the file the user asked for, which keeps what was recorded until then — not the
    partial file it was written through."""
    import resource  # POSIX only, as the limit is

    out = tmp_path / "full.mcap"
    scene = load_scene("paper")

    def limit() -> None:  # 200 kB: reached within seconds of camera frames
        resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))

    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0",)) as sitl:
        args = ["--connect", f"tcp:127.0.0.1:{sitl.ports[0]}", "-o", str(out)]
        done = subprocess.run(
            [sys.executable, "-m", "uavtool", "record", *args, "--camera", "sim", "--rate", "5"],
            cwd=REPO,
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=limit,  # the child's limit alone, set before it runs
            check=False,
        )
    assert done.returncode == 2, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith(f"uavtool: error: {out}: cannot write: File too large"), last
    assert "kept here" in last and ".partial" not in last
    assert out.exists() and not list(tmp_path.glob("*.partial"))
    with RecordingReader(out) as reader:
        assert sum(1 for _ in reader.messages([TELEMETRY])) > 0


class _StallingCamera:
    """A live camera that gives two new frames, then the same one for ever (a stalled
    MJPEG stream)."""

    name = "stalling"

    def __init__(self, intrinsics: Any) -> None:
        self.intrinsics = intrinsics
        self.captured_at_s: float | None = None
        self._taken = 0

    def capture(self, pose: Any) -> Any:
        del pose
        self._taken += 1
        if self._taken <= 2:
            self.captured_at_s = time.monotonic()
        k = self.intrinsics
        return np.full((k.height_px, k.width_px, 3), 90, np.uint8)

    def close(self) -> None:
        pass


def test_a_link_that_dies_before_the_duration_is_said_on_the_last_line_and_exit_3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`record --duration` over a link whose vehicle falls silent: the file is whole and
    kept, its last line says what it lacks, and the exit code is 3 (not 0, "stopped")."""
    from uavtool.recorder import session

    monkeypatch.setattr(session, "LOST_S", 1.0)  # 10 s in real use
    out = tmp_path / "dead.mcap"
    scene = load_scene("paper")
    port = free_udp_port()
    sitl = vehicle(scene, endpoints=(f"udpout:127.0.0.1:{port}",)).__enter__()
    threading.Timer(1.5, lambda: sitl.__exit__(None, None, None)).start()  # the radio dies
    args = ["record", "--connect", f"udpin:127.0.0.1:{port}", "-o", str(out)]
    result = CliRunner().invoke(cli, [*args, "--duration", "4", "--camera", "none"])
    assert result.exit_code == 3, result.output
    last = result.output.strip().splitlines()[-1]
    assert last.startswith("incomplete: link: nothing heard from the vehicle for the last ")
    assert summarize(out).whole
    with RecordingReader(out) as reader:
        kept = dict(reader.metadata)["record_result"]
    assert kept["stopped"] == "duration" and kept["gaps"].startswith("link: nothing heard")


def test_a_camera_that_stalls_is_said_on_the_last_line_and_exit_3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from uavtool.runner import camera

    monkeypatch.setitem(
        camera.SOURCES,
        "opencv",
        lambda _arg, _scene, intrinsics, _seed: _StallingCamera(intrinsics),
    )
    out = tmp_path / "stalled.mcap"
    scene = load_scene("paper")
    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0",)) as sitl:
        args = ["record", "--connect", f"tcp:127.0.0.1:{sitl.ports[0]}", "-o", str(out)]
        result = CliRunner().invoke(
            cli, [*args, "--duration", "4", "--camera", "opencv:0", "--rate", "5"]
        )
    assert result.exit_code == 3, result.output
    last = result.output.strip().splitlines()[-1]
    assert last.startswith("incomplete: camera: nothing new for the last "), last
    assert summarize(out).whole


def test_a_recording_that_got_all_it_asked_for_exits_0(tmp_path: Path) -> None:
    out = tmp_path / "whole.mcap"
    scene = load_scene("paper")
    with vehicle(scene, endpoints=("tcpin:127.0.0.1:0",)) as sitl:
        args = ["record", "--connect", f"tcp:127.0.0.1:{sitl.ports[0]}", "-o", str(out)]
        result = CliRunner().invoke(
            cli, [*args, "--duration", "3", "--camera", "sim", "--scene", "paper", "--rate", "2"]
        )
    assert result.exit_code == 0, result.output
    assert "incomplete" not in result.output
