"""`MissionLogger` on hand-made observations and outputs, as `uavtool fly --rerun` calls it."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.view.rrd import read_rrd
from uavtool.view import open_viewer, statustext_level


def _telemetry(ms: int, x: float, *, mode: str = "GUIDED") -> dict[str, object]:
    return {
        "type": "Telemetry",
        "time_boot_ms": ms,
        "pos_enu_m": [x, 0.0, 10.0],
        "vel_enu_m_s": [3.0, 4.0, 0.0],
        "heading_deg": 90.0,
        "mode": mode,
        "armed": True,
        "landed": False,
        "gimbal_pitch_deg": -90.0,
        "gimbal_yaw_deg": 0.0,
        "battery_pct": 90,
    }


def test_outputs_take_the_vehicle_time_of_the_observation_before(tmp_path: Path) -> None:
    out = tmp_path / "live.rrd"
    viewer = open_viewer(save=out)
    log = viewer.logger
    log.output(1, {"type": "Event", "level": "info", "text": "before any telemetry"})
    log.observation(1, _telemetry(5_000, 0.0))
    log.output(2, {"type": "Event", "level": "warning", "text": "after"})
    log.observation(2, {"type": "CommandResult", "action_id": 3, "accepted": False, "detail": "no"})
    log.statustext(3, "PreArm: bad compass")
    viewer.close()
    data, _ = read_rrd(out)
    mission = data.rows["log/mission"]
    assert [r["TextLog:text"] for r in mission] == [["before any telemetry"], ["after"]]
    assert "vehicle_time" not in mission[0]  # no vehicle time known yet
    assert mission[1]["vehicle_time"] == 5_000_000_000
    assert mission[1]["TextLog:level"] == ["WARN"]
    assert data.last("log/commands")["TextLog:text"] == ["action 3: no"]
    assert data.last("log/vehicle")["TextLog:level"] == ["ERROR"]
    # live without receive times: the vehicle's clock only
    assert data.timelines["log/vehicle"] == {"vehicle_time"}


def test_live_telemetry_is_sent_in_small_batches(tmp_path: Path) -> None:
    viewer = open_viewer(save=tmp_path / "live.rrd", batch=3)
    log = viewer.logger
    for i in range(5):
        log.observation(i, _telemetry(1_000 + 100 * i, float(i)), log_time_ns=10**18 + i)
    assert log.telemetry.pending == 2  # the first three went out already
    viewer.close()
    data, _ = read_rrd(tmp_path / "live.rrd")
    speeds = data.column("plots/telemetry/speed_m_s", "Scalars:scalars")
    assert speeds == [[5.0]] * 5  # horizontal speed of (3, 4, 0) m/s
    assert data.column("plots/telemetry/altitude_m", "log_time") == [10**18 + i for i in range(5)]
    # the mode is logged once, when it changes
    assert [r["TextLog:text"] for r in data.rows["log/vehicle"]] == [["mode GUIDED, armed"]]


def test_route_chunks_join_end_to_start(tmp_path: Path) -> None:
    viewer = open_viewer(save=tmp_path / "route.rrd")
    log = viewer.logger
    log.telemetry.route_chunk, log.telemetry.route_step = 4, 2
    for i in range(11):
        log.observation(i, _telemetry(1_000 + 100 * i, float(i)))
    viewer.close()
    data, _ = read_rrd(tmp_path / "route.rrd")
    chunks = sorted(data.entities("world/route/"))
    xs = [[p[0] for p in data.last(c)["LineStrips3D:strips"][0]] for c in chunks]
    assert xs == [[0, 1, 2, 3], [3, 4, 5, 6], [6, 7, 8, 9], [9, 10]]
    # a chunk grows every route_step samples: its rows are its partial strips
    first = [len(r["LineStrips3D:strips"][0]) for r in data.rows[chunks[0]]]
    assert first == [2, 4]


def test_photo_then_shapes_draw_over_that_frame(tmp_path: Path) -> None:
    viewer = open_viewer(save=tmp_path / "photo.rrd")
    log = viewer.logger
    log.observation(1, _telemetry(2_000, 0.0))
    photo = {
        "type": "Photo",
        "frame_index": 0,
        "tag": "overview",
        "time_boot_ms": 2_000,
        "pose": {"pos_enu_m": [0.0, 0.0, 45.0], "heading_deg": 0.0, "pitch_deg": -90.0},
        "intrinsics": {
            "width_px": 64, "height_px": 48, "fx_px": 50.0, "fy_px": 50.0,
            "cx_px": 31.5, "cy_px": 23.5,
        },
    }  # fmt: skip
    log.observation(2, photo, b"\x89PNG fake")
    square = [[10.0, 10.0], [20.0, 10.0], [20.0, 20.0], [10.0, 20.0]]
    shape = {"colour_rgb": [200, 30, 30], "polygon_px": square, "holes_px": [square[:3]]}
    log.output(3, {"type": "Shapes", "frame_index": 0, "tag": "overview", "shapes": [shape]})
    log.output(4, {"type": "Shapes", "frame_index": 5, "tag": "top", "shapes": [shape]})
    viewer.close()
    data, _ = read_rrd(tmp_path / "photo.rrd")
    (pinhole,) = data.column("world/camera/image", "Pinhole:resolution")
    assert pinhole == [[64.0, 48.0]]
    strips = data.column("world/camera/image/overlay/shapes", "LineStrips2D:strips")
    assert len(strips) == 1  # frame 5's shapes are not drawn over frame 0
    outline, hole = strips[0]
    # closed, and moved from OpenCV's pixel centres to Rerun's (+0.5)
    assert outline[0] == outline[-1] == [10.5, 10.5]
    assert len(outline) == 5 and len(hole) == 4
    assert log.counts.frames == 1 and log.counts.shapes == 2


@pytest.mark.parametrize(
    ("severity", "level"),
    [(0, "CRITICAL"), (2, "CRITICAL"), (3, "ERROR"), (4, "WARN"), (6, "INFO"), (7, "DEBUG")],
)
def test_statustext_levels(severity: int, level: str) -> None:
    assert statustext_level(severity) == level
