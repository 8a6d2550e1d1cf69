"""The example missions, flown on the built-in vehicle: what each promises shows in its
recording."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.images import png_decode
from uavtool.recording import RecordingReader
from uavtool.world import load_scene


def _fly(tmp_path: Path, *args: str) -> tuple[Path, str]:
    rec = tmp_path / "flight.mcap"
    result = CliRunner().invoke(cli, ["fly", "-q", "--output", str(rec), *args])
    assert result.exit_code == 0, result.output
    return rec, result.output


def _payloads(rec: Path, topic: str) -> list[dict[str, object]]:
    with RecordingReader(rec) as reader:
        return [dict(e.value.payload) for e in reader.entries([topic])]


def test_the_survey_maps_every_building_where_it_stands(tmp_path: Path) -> None:
    rec, out = _fly(tmp_path, "--mission", "survey", "--set", "survey.mosaic_m_per_px=0.5")
    assert 'result         mosaic: {"photos": 4, "covered": 1.0}' in out, out
    with RecordingReader(rec) as reader:
        (entry,) = list(reader.entries(["/mission/pictures"]))
    assert entry.value.frame_id == "mosaic"
    image = png_decode(entry.value.data, where="mosaic")
    assert image.shape == (160, 160, 3)  # ±40 m at 0.5 m a pixel
    scene = load_scene("paper")
    for building in scene.buildings:  # each footprint's centre shows the building's colour
        xs = [x for blk in building.blocks for x, _ in blk.footprint_enu_m]
        ys = [y for blk in building.blocks for _, y in blk.footprint_enu_m]
        x, y = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
        row, col = int((40.0 - y) / 0.5), int((x + 40.0) / 0.5)
        colour = image[row - 1 : row + 2, col - 1 : col + 2].reshape(-1, 3).mean(axis=0)
        assert np.abs(colour - np.array(building.color_rgb)).max() < 60, building.name
    ground = image[2:10, 2:10].reshape(-1, 3)  # a corner of the square: ground
    assert np.abs(ground - scene.ground_rgb).max() < 30
    # Rerun shows it too
    shown = CliRunner().invoke(cli, ["view", str(rec), "--save", str(tmp_path / "s.rrd")])
    assert shown.exit_code == 0 and "5 frames" in shown.output and "1 picture" in shown.output


def test_the_orbit_photographs_its_centre_from_every_side(tmp_path: Path) -> None:
    rec, out = _fly(
        tmp_path, "--mission", "orbit", "--set", "orbit.step_deg=90", "--set", "orbit.aim_m=5"
    )
    assert "completed: 4 photos round (0, 0)" in out, out
    photos = [p for p in _payloads(rec, "/mission/observations") if p["type"] == "Photo"]
    assert len(photos) == 4
    for photo in photos:
        pose = photo["pose"]
        assert isinstance(pose, dict)
        x, y, z = pose["pos_enu_m"]
        assert math.hypot(x, y) == pytest.approx(30.0, abs=1.0)
        to_centre = math.degrees(math.atan2(-x, -y)) % 360.0
        assert abs((pose["heading_deg"] - to_centre + 180.0) % 360.0 - 180.0) < 4.0
        assert pose["pitch_deg"] == pytest.approx(-math.degrees(math.atan2(z - 5.0, 30.0)), abs=2.5)
