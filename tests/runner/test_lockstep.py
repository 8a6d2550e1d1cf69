"""Lockstep: a flight of the built-in vehicle is a function of its inputs — the same bytes at
any speed-up, under any load, with every fault injected — and its recording runs on sim time."""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.camera import CameraPose
from uavtool.cli import cli
from uavtool.mission import Params, Status
from uavtool.mission.params import with_overrides
from uavtool.recording import RecordingReader, summarize
from uavtool.runner.camera import SimCamera
from uavtool.runner.fly import FlyConfig, fly
from uavtool.sitl.lockstep import SIM_EPOCH_NS, LockstepTransport

# The link is cut for good 15 s into the flight; the mission gives up 5 s later: a short
# flight that still crosses the vehicle, the link, the camera and the mission.
_SHORT = {
    "params": with_overrides(Params(), {"mission.link_lost_abort_s": "5"}),
    "link_outages_s": ((15.0, 1e6),),
}


def _fly(path: Path, **options: object) -> bytes:
    fly(FlyConfig(record=path, **options))  # type: ignore[arg-type]
    return path.read_bytes()


@pytest.fixture(scope="module")
def paper(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("lockstep") / "paper.mcap"
    _fly(path, record_in_process=True)
    return path


def test_same_inputs_give_the_same_bytes(paper: Path, tmp_path: Path) -> None:
    assert _fly(tmp_path / "again.mcap") == paper.read_bytes()


def test_the_writer_process_writes_the_same_bytes(paper: Path, tmp_path: Path) -> None:
    """fly picks the writer by the machine's load; the file must not tell which."""
    assert _fly(tmp_path / "process.mcap", record_in_process=False) == paper.read_bytes()


@pytest.mark.parametrize(
    ("choice", "spare", "used"),
    [
        ("process", False, "ProcessWriter"),
        ("thread", True, "RecordingWriter"),
        ("auto", True, "ProcessWriter"),
        ("auto", False, "RecordingWriter"),
    ],
)
def test_fly_writes_where_it_is_told(
    choice: str, spare: bool, used: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``uavtool fly --writer process|thread`` takes that writer whatever the load; ``auto``
    asks whether a core is free. The files are the same (above)."""
    import uavtool.runner.fly as runner
    from uavtool.recording import writer

    made: list[str] = []
    # fly imports the MCAP writer only when it writes on the flight's thread
    for module, name in ((runner, "ProcessWriter"), (writer, "RecordingWriter")):
        real = getattr(module, name)

        def spy(*args: object, _real: type = real, _name: str = name, **kw: object) -> object:
            made.append(_name)
            return _real(*args, **kw)

        monkeypatch.setattr(module, name, spy)
    monkeypatch.setattr(runner, "core_to_spare", lambda: spare)
    out = tmp_path / "f.mcap"
    short = ["--link-outage", "15:1e6", "--set", "mission.link_lost_abort_s=5"]  # as _SHORT
    result = CliRunner().invoke(cli, ["fly", "--writer", choice, "-o", str(out), "-q", *short])
    assert result.exit_code == 1, result.output  # aborted: the link is lost for good
    assert made == [used]
    assert summarize(out).whole


def test_no_recording_has_no_writer_to_choose() -> None:
    result = CliRunner().invoke(cli, ["fly", "--no-record", "--writer", "process"])
    assert result.exit_code == 2
    assert "--writer process: there is no recording to write (--no-record)" in result.output


def test_a_different_input_gives_a_different_file(paper: Path, tmp_path: Path) -> None:
    """The comparison above can fail: one vehicle parameter changes the flight."""
    assert _fly(tmp_path / "slow.mcap", vehicle_params=(("WPNAV_SPEED", 300.0),)) != (
        paper.read_bytes()
    )


def test_speedup_is_only_a_cap(tmp_path: Path) -> None:
    paced = _fly(tmp_path / "x5.mcap", speedup=5.0, **_SHORT)
    assert paced == _fly(tmp_path / "max.mcap", **_SHORT)
    with RecordingReader(tmp_path / "x5.mcap") as reader:
        start, end = reader.time_range_ns
    assert end - start > 15e9  # it did fly past the outage, at 5x


@contextmanager
def _busy_processes(n: int) -> Iterator[None]:
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
            p.wait()


def test_a_busy_machine_gives_the_same_bytes(paper: Path, tmp_path: Path) -> None:
    with _busy_processes(2):
        loaded = _fly(tmp_path / "loaded.mcap", speedup=300.0)
    assert loaded == paper.read_bytes()


@pytest.mark.parametrize(
    "faults",
    [
        pytest.param({"wind": (6.0, 120.0), "seed": 7}, id="wind"),
        pytest.param(
            {"vehicle_params": (("SIM_WIND_TURB", 2.0),), "wind": (4.0, 300.0), "seed": 3},
            id="gusts",
        ),
        pytest.param(
            {"noise": True, "seed": 11, "vehicle_params": (("SIM_GPS_NOISE", 0.5),)},
            id="noise",
        ),
        pytest.param({"link_outages_s": ((70.0, 15.0),)}, id="link-outage"),
        pytest.param(_SHORT, id="link-lost"),
    ],
)
def test_every_fault_injection_is_reproducible(tmp_path: Path, faults: dict[str, object]) -> None:
    assert _fly(tmp_path / "a.mcap", **faults) == _fly(tmp_path / "b.mcap", **faults)


def test_link_lost_for_good_ends_on_vehicle_time(tmp_path: Path) -> None:
    summary = fly(FlyConfig(record=tmp_path / "lost.mcap", **_SHORT))  # type: ignore[arg-type]
    assert summary.outcome.status is Status.LINK_LOST
    # The link is cut 15 s after boot; the mission gives up after 5 s of silence.
    assert "no link for" in summary.outcome.reason
    assert 19.0 <= summary.vehicle_time_s <= 22.0


def test_the_recording_clock_is_sim_time(paper: Path) -> None:
    with RecordingReader(paper) as reader:
        start, end = reader.time_range_ns
        messages = list(reader.messages())
        meta = dict(reader.metadata)
    assert start >= SIM_EPOCH_NS
    assert 130e9 < end - start < 300e9  # the flight's vehicle time (minutes), not the wall's
    assert all(m.publish_time_ns == m.log_time_ns for m in messages)
    assert meta["vehicle"]["clock"] == "lockstep"
    assert "command_line" not in meta  # paths and speed-ups are not inputs of the flight


def test_info_reports_vehicle_time_rates(paper: Path) -> None:
    result = CliRunner().invoke(cli, ["info", str(paper)])
    assert result.exit_code == 0, result.output
    line = next(x for x in result.output.splitlines() if "/mavlink/in/ATTITUDE " in x)
    assert "10.0" in line.split("msgs")[1]


@pytest.mark.parametrize("bad", ["0", "-3", "fast", "inf", "nan"])
def test_speedup_must_be_positive_or_max(tmp_path: Path, bad: str) -> None:
    result = CliRunner().invoke(cli, ["fly", "--no-record", "--speedup", bad])
    assert result.exit_code == 2
    assert "--speedup" in result.output and "'max'" in result.output


def test_photos_are_rendered_where_the_vehicle_really_is(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With 2 m of GPS noise the telemetry (and so the mission) is wrong about the position;
    the simulated camera is not: it renders at the vehicle's true pose at that instant."""
    truths: list[CameraPose] = []
    rendered: list[CameraPose] = []
    true_pose = LockstepTransport.camera_pose

    def spy_truth(self: LockstepTransport) -> CameraPose:
        truths.append(true_pose(self))
        return truths[-1]

    capture = SimCamera.capture

    def spy_capture(self: SimCamera, pose: CameraPose) -> object:
        rendered.append(pose)
        return capture(self, pose)

    monkeypatch.setattr(LockstepTransport, "camera_pose", spy_truth)
    monkeypatch.setattr(SimCamera, "capture", spy_capture)
    path = tmp_path / "noisy.mcap"
    fly(FlyConfig(record=path, vehicle_params=(("SIM_GPS_NOISE", 2.0),), seed=4))
    assert rendered and rendered == truths  # the paper scene's home is the vehicle's
    with RecordingReader(path) as reader:
        told = [
            e.value.payload["pose"]["pos_enu_m"]
            for e in reader.entries(["/mission/observations"])
            if e.value.payload["type"] == "Photo"  # type: ignore[union-attr]
        ]
    assert len(told) == len(rendered)
    errors = [math.dist(t, r.pos_enu_m) for t, r in zip(told, rendered, strict=True)]
    assert max(errors) > 0.5  # the noise is real: the mission is told another pose
