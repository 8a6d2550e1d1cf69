"""`uavtool record --vehicles N`: a fleet someone else flies, heard on one link (every vehicle
sends to one UDP port), each vehicle recorded under /uavK in its own frame, the MAVLink
frames once; waiting for N that never come, one falling silent, direct mode."""

from __future__ import annotations

import json
import math
import threading
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner

from tests.recorder.fleet_flight import (
    SPACING_M,
    altitude_m,
    fly_all,
    shared_port_fleet,
)
from tests.recorder.flight import free_udp_port, start_record
from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.images import png_decode
from uavtool.mavlink import FrameParser
from uavtool.mavlink import mavlink as M
from uavtool.recorder import RecordConfig, Stop, record
from uavtool.recording import CompressedImage, JsonDocument, LogEntry, RecordingReader
from uavtool.recording.fleet import vehicle_prefix
from uavtool.recording.topics import FIX, FRAMES, IMAGE, TELEMETRY, VEHICLE_EVENTS
from uavtool.recording.values import LocationFix
from uavtool.world import load_scene, render

SYSIDS = (1, 2, 3)


@dataclass(frozen=True)
class RecordedFleet:
    path: Path
    returncode: int
    stdout: str
    stderr: str


@pytest.fixture(scope="module")
def recorded_fleet(tmp_path_factory: pytest.TempPathFactory) -> RecordedFleet:
    """Three vehicles flown at once by three pilots, recorded passively on their shared UDP
    port with a simulated camera each, until all have landed: ~6 s of wall time."""
    path = tmp_path_factory.mktemp("fleet") / "fleet.mcap"
    with shared_port_fleet(len(SYSIDS)) as shared:
        args = [
            *("--connect", f"udpin:127.0.0.1:{shared.port}", "-o", str(path)),
            *("--vehicles", str(len(SYSIDS)), "--until-landed"),
            *("--camera", "sim", "--scene", "paper", "--rate", "1"),
        ]
        proc, said = start_record(args)
        try:
            fly_all(shared.fleet)
            stdout, stderr = proc.communicate(timeout=30)
        finally:
            proc.kill()
    return RecordedFleet(path, proc.returncode, stdout, said + stderr)


def _read(path: Path) -> dict[int, dict[str, list[Any]]]:
    """Per vehicle: its telemetry, fixes, events, frame records and images."""
    out: dict[int, dict[str, list[Any]]] = {}
    topics = {}
    for k in SYSIDS:
        out[k] = {"telemetry": [], "fix": [], "events": [], "frames": [], "images": []}
        p = vehicle_prefix(k)
        topics |= {
            p + TELEMETRY: (k, "telemetry"),
            p + FIX: (k, "fix"),
            p + VEHICLE_EVENTS: (k, "events"),
            p + FRAMES: (k, "frames"),
            p + IMAGE: (k, "images"),
        }
    with RecordingReader(path) as reader:
        assert reader.health.whole
        present = set(reader.topics())
        for e in reader.entries([t for t in topics if t in present]):
            k, kind = topics[e.topic]
            v = e.value
            if isinstance(v, JsonDocument):
                out[k][kind].append(dict(v.payload))
            elif isinstance(v, LocationFix):
                out[k][kind].append(v)
            elif isinstance(v, LogEntry):
                out[k][kind].append(v.message)
            elif isinstance(v, CompressedImage):
                out[k][kind].append(v.data)
    return out


def _homes() -> dict[int, GeoPoint]:
    from uavtool.sitl.fleet import OffsetLine, line_homes

    home = load_scene("paper").home
    return dict(
        zip(SYSIDS, line_homes(home, len(SYSIDS), OffsetLine(90.0, SPACING_M)), strict=True)
    )


def test_every_vehicle_is_recorded_in_its_own_frame(recorded_fleet: RecordedFleet) -> None:
    r = recorded_fleet
    assert r.returncode == 0, r.stderr
    assert "(landed), 3 vehicles, " in r.stdout and " 0 out, " in r.stdout  # passive
    for k in SYSIDS:
        assert f"heard vehicle sysid {k}" in r.stderr
        assert f"; vehicle {k}: " in r.stdout
    per_vehicle = _read(r.path)
    homes = _homes()
    counts = [len(per_vehicle[k]["telemetry"]) for k in SYSIDS]
    assert min(counts) > 100 and max(counts) - min(counts) < 0.2 * max(counts), counts
    for k in SYSIDS:
        v = per_vehicle[k]
        telemetry = v["telemetry"]
        # its own frame, around its own home: it starts at 0, 0, 0, lands 3 m north
        first, last = telemetry[0], telemetry[-1]
        assert math.dist(first["pos_enu_m"], (0.0, 0.0, 0.0)) < 0.3, (k, first)
        assert math.dist(last["pos_enu_m"], (0.0, 3.0, 0.0)) < 0.3, (k, last)
        assert not first["armed"] and not last["armed"]
        top = max(t["pos_enu_m"][2] for t in telemetry)
        assert top == pytest.approx(altitude_m(k), abs=0.4)
        # … and its fixes on the map, where it stands
        fix = v["fix"][0]
        e, n, _ = enu_from_geo(homes[k], GeoPoint(fix.latitude_deg, fix.longitude_deg, 0.0))
        assert math.hypot(e, n) < 0.3, (k, e, n)
        assert len(v["fix"]) == len(telemetry)
        assert {"armed", "disarmed", "mode GUIDED → LAND"} <= set(v["events"])
        assert v["events"][-1] == "recording stopped: landed"
        # its own camera's frames, its poses in its own frame
        assert len(v["frames"]) >= 2 and len(v["images"]) == len(v["frames"])


def test_each_camera_sees_the_scene_from_its_own_vehicle(recorded_fleet: RecordedFleet) -> None:
    scene = load_scene("paper")
    per_vehicle = _read(recorded_fleet.path)
    homes = _homes()
    for k in SYSIDS:
        record, png = per_vehicle[k]["frames"][-1], per_vehicle[k]["images"][-1]
        x, y, z = record["pose"]["pos_enu_m"]
        assert math.hypot(x, y) < 3.5  # in its own frame
        east, north, _ = enu_from_geo(scene.home, homes[k])
        pose = CameraPose(
            (x + east, y + north, z), record["pose"]["heading_deg"], record["pose"]["pitch_deg"]
        )
        i = record["intrinsics"]
        intrinsics = Intrinsics.from_hfov(width_px=i["width_px"], height_px=i["height_px"])
        assert np.array_equal(png_decode(png, where="frame"), render(scene, pose, intrinsics))


def test_info_lists_the_vehicles_and_the_tools_take_the_file(
    recorded_fleet: RecordedFleet, tmp_path: Path
) -> None:
    path = str(recorded_fleet.path)
    runner = CliRunner()
    result = runner.invoke(cli, ["info", path])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert any(
        x.startswith("recorded:  by uavtool record (no mission), stopped: landed") for x in lines
    )
    for k in SYSIDS:
        line = next(x for x in lines if x.startswith(f"vehicle {k}: "))
        assert "telemetry samples" in line and f"(topics /uav{k}/…)" in line
    data = json.loads(runner.invoke(cli, ["info", "--json", path]).output)
    assert sorted(data["vehicles"]) == ["1", "2", "3"]
    with RecordingReader(recorded_fleet.path) as reader:
        meta = dict(reader.metadata)
        raw = sum(1 for _ in reader.messages(["/mavlink/raw"]))
    assert json.loads(meta["record"]["vehicle_sysids"]) == list(SYSIDS)
    assert len(json.loads(meta["record"]["origins"])) == len(SYSIDS)
    assert meta["fleet"]["vehicles"] == "3"
    homes = json.loads(meta["crew"]["homes_en_m"])
    assert [round(e) for e, _ in homes] == [0, 10, 20]

    # replay has no mission to replay: one line, as for one vehicle's record file
    result = runner.invoke(cli, ["replay", "--check", path])
    assert result.exit_code == 2
    assert result.output.count("\n") == 1 and "not a mission recording" in result.output

    tlog = tmp_path / "fleet.tlog"
    result = runner.invoke(cli, ["export", path, "--tlog", str(tlog)])
    assert result.exit_code == 0, result.output
    assert f"wrote {raw} MAVLink frames" in result.output
    senders = Counter(f.msg.get_srcSystem() for f in FrameParser().feed(tlog.read_bytes()))
    assert set(SYSIDS) <= set(senders)


def test_view_shows_every_vehicle_at_its_home(
    recorded_fleet: RecordedFleet, tmp_path: Path
) -> None:
    """`view --save` puts each vehicle's route and camera frames under world/uavK, that frame
    placed at its home (``crew.homes_en_m``), as a fleet that `fly` flies is shown."""
    from tests.view.rrd import read_rrd

    out = tmp_path / "fleet.rrd"
    result = CliRunner().invoke(cli, ["view", str(recorded_fleet.path), "--save", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.startswith(f"wrote {out}: 3 vehicles, "), result.output
    data, _ = read_rrd(out)
    with RecordingReader(recorded_fleet.path) as reader:
        homes = json.loads(dict(reader.metadata)["crew"]["homes_en_m"])
    per_vehicle = _read(recorded_fleet.path)
    for k in SYSIDS:
        ((placed,),) = data.column(f"world/uav{k}", "Transform3D:translation")
        assert placed == pytest.approx([*homes[k - 1], 0.0], abs=1e-3)
        route: list[list[float]] = []
        for chunk in sorted(data.entities(f"world/uav{k}/route/")):
            strip = data.last(chunk)["LineStrips3D:strips"][0]
            route += strip[1:] if route else strip
        world = np.asarray(route) + np.asarray(placed)
        telemetry = [t["pos_enu_m"] for t in per_vehicle[k]["telemetry"] if t["time_boot_ms"] > 0]
        expected = np.asarray(telemetry) + np.asarray([*homes[k - 1], 0.0])
        np.testing.assert_allclose(world, expected, rtol=0.0, atol=1e-3)
        frames = len(per_vehicle[k]["frames"])
        assert frames >= 2
        assert len(data.column(f"world/uav{k}/camera/image", "EncodedImage:blob")) == frames
        assert f"map/uav{k}/vehicle" in data.entities()
        assert data.column(f"log/uav{k}/vehicle", "TextLog:text")  # its events
    assert not data.entities("world/route/") and "world/vehicle" not in data.entities()


def test_fewer_vehicles_than_asked_for_is_one_line_exit_2_and_no_file(tmp_path: Path) -> None:
    out = tmp_path / "two.mcap"
    with shared_port_fleet(2) as shared:
        args = ["record", "--connect", f"udpin:127.0.0.1:{shared.port}", "-o", str(out)]
        result = CliRunner().invoke(cli, [*args, "--vehicles", "3", "--timeout", "2"])
    assert result.exit_code == 2
    message = result.output.strip().splitlines()[-1]
    assert f"udpin:127.0.0.1:{shared.port}: heard vehicles 1, 2 of 3 in 2 s" in message
    assert "nothing was sent (passive)" in message
    assert list(tmp_path.iterdir()) == []


def test_a_real_camera_for_a_fleet_is_refused(tmp_path: Path) -> None:
    port = free_udp_port()
    args = ["record", "--connect", f"udpin:127.0.0.1:{port}", "-o", str(tmp_path / "x.mcap")]
    result = CliRunner().invoke(cli, [*args, "--vehicles", "2", "--camera", "opencv:0"])
    assert result.exit_code == 2
    assert "--camera opencv:0 with --vehicles 2" in result.output
    assert result.output.count("\n") == 1 and list(tmp_path.iterdir()) == []


def test_a_vehicle_that_falls_silent_while_the_others_fly_is_the_last_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Vehicle 3's radio dies soon after the recording starts; 1 and 2 fly and land: the
    recording stops when they have, keeps everything, and says what it lacks (exit 3)."""
    from uavtool.recorder import session

    monkeypatch.setattr(session, "LOST_S", 0.5)  # 10 s in real use
    out = tmp_path / "silent.mcap"
    flown: list[BaseException | None] = []

    def pilots(fleet: Any) -> None:  # the recorder's signal handlers need the main thread
        try:
            _wait_for(lambda: any(tmp_path.glob("*.partial")), "the recording", 10.0)
            fly_all(fleet, [1, 2])
            flown.append(None)
        except BaseException as exc:
            flown.append(exc)

    # vehicle 3: nothing in or out from 14 s of sim time on (1.75 s of wall time: heard by
    # then, and silent for over 1 s of the ~3 s the others take to fly)
    with shared_port_fleet(3, silent_from_s={3: 14.0}) as shared:
        thread = threading.Thread(target=pilots, args=(shared.fleet,))
        thread.start()
        args = ["record", "--connect", f"udpin:127.0.0.1:{shared.port}", "-o", str(out)]
        args += ["--vehicles", "3", "--until-landed", "--timeout", "5"]
        result = [CliRunner().invoke(cli, args)]
        thread.join()
    assert flown == [None], flown
    assert result, "record did not stop"
    r = result[0]
    assert r.exit_code == 3, r.output
    lines = r.output.strip().splitlines()
    assert "(landed), 3 vehicles" in lines[-2]
    assert lines[-1].startswith("incomplete: link: nothing heard from vehicle 3 for the last ")
    per_vehicle = _read(out)
    assert max(t["pos_enu_m"][2] for t in per_vehicle[3]["telemetry"]) < 0.1
    assert "link: nothing heard for 0.5 s: lost" in per_vehicle[3]["events"]
    for k in (1, 2):
        assert max(t["pos_enu_m"][2] for t in per_vehicle[k]["telemetry"]) > 2.5


def test_a_fleet_that_falls_silent_is_lost(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from uavtool.recorder import session

    monkeypatch.setattr(session, "LOST_S", 0.5)  # 10 s in real use
    with shared_port_fleet(2, silent_from_s={1: 12.0, 2: 12.0}) as shared:
        config = RecordConfig(
            connect=f"udpin:127.0.0.1:{shared.port}",
            output=tmp_path / "lost.mcap",
            until_landed=True,
            timeout_s=5.0,
            vehicles=2,
        )
        summary = record(config)
    assert summary.stop is Stop.VEHICLE_LOST
    assert [g.split(" for the last")[0] for g in summary.gaps] == [
        "link: nothing heard from vehicle 1",
        "link: nothing heard from vehicle 2",
    ]


def test_direct_mode_asks_every_recorded_vehicle_for_its_streams(tmp_path: Path) -> None:
    """Three vehicles, two recorded (``--vehicles 2``): each of the two is asked for its
    streams at the address it speaks from; the third is not recorded, nor asked."""
    asked: Counter[int] = Counter()

    def tap(direction: str, link: Any, raw: bytes) -> None:
        if direction == "in" and link.name.startswith("udp"):
            for frame in FrameParser().feed(raw):
                msg = frame.msg
                if msg.get_type() == "COMMAND_LONG" and msg.target_system == link.encoder.srcSystem:
                    asked[msg.target_system] += msg.command == M.MAV_CMD_SET_MESSAGE_INTERVAL

    said: list[str] = []
    with shared_port_fleet(3, tap=tap) as shared:
        config = RecordConfig(
            connect=f"udpin:127.0.0.1:{shared.port}",
            output=tmp_path / "direct.mcap",
            direct=True,
            duration_s=2.5,
            vehicles=2,
        )
        summary = record(config, status=said.append)
    assert summary.stop is Stop.DURATION and summary.messages_out > 0
    recorded = [v.sysid for v in summary.vehicles]
    assert len(recorded) == 2 and all(v.telemetry > 10 for v in summary.vehicles)
    assert sorted(asked) == sorted(recorded) and min(asked.values()) >= 7
    (left,) = set(SYSIDS) - set(recorded)
    assert f"heard vehicle sysid {left} too: not recorded (--vehicles 2)" in said


def _wait_for(check: Any, what: str, timeout: float = 30.0) -> None:
    import time

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if check():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")
