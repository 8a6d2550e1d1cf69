"""Cameras stand, and ways below the ceiling run, only where a photo from above saw that no
building the mission does not know stands: over the ground the overview saw, or where a
look down from the ceiling (a peek) shows none near (issue 26)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.mission.driver import run, target_rgb
from tests.mission.fakes import FakeVehicle
from tests.mission.scenes import on_grey_ground
from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.mission import GoTo, MissionInputs, SearchMission, TakePhoto
from uavtool.mission.base import Wait
from uavtool.mission.ground import standing_regions
from uavtool.mission.observations import Photo
from uavtool.mission.params import Params
from uavtool.mission.peek import Peek
from uavtool.recording import JsonDocument, RecordingReader
from uavtool.recording.topics import OBSERVATIONS
from uavtool.runner.fly import FlyConfig, fly
from uavtool.world import Scene, render, scene_from_dict

DATA = Path(__file__).parent / "data"
K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)


def _scene(buildings: list[tuple[float, float, float, float]]) -> Scene:
    """Square buildings (centre east, north, half side, height)."""
    return on_grey_ground(
        "peek",
        "b0",
        [
            {
                "name": f"b{i}",
                "color": [217, 84 + 40 * i, 54],
                "blocks": [
                    {
                        "footprint": [
                            [cx - h, cy - h],
                            [cx + h, cy - h],
                            [cx + h, cy + h],
                            [cx - h, cy + h],
                        ],
                        "base_m": 0.0,
                        "top_m": top,
                    }
                ],
            }
            for i, (cx, cy, h, top) in enumerate(buildings)
        ],
    )


@pytest.mark.parametrize("top_m", [8.0, 45.0, 90.0])
def test_a_peek_places_a_building_no_nearer_than_its_footprint(top_m: float) -> None:
    """A 10 m square building 30 m east of the nadir, low or a tower: from 117 m its roof
    and walls land further out than its base, so the nearest it may stand to the nadir is
    its footprint's 25 m, whatever its height; 3 m from its wall nothing is clear."""
    scene = _scene([(30.0, 0.0, 5.0, top_m)])
    pose = CameraPose((0.0, 0.0, 117.0), 0.0, -90.0)
    peek = Peek.of(Photo(0, 0, "peek", 0, pose, K, render(scene, pose, K)), Params().vectorize)
    assert peek is not None and len(peek.buildings) == 1
    assert peek.clear_m((0.0, 0.0)) == pytest.approx(25.0, abs=0.6)
    assert peek.clear_m((22.0, 0.0)) < 3.5
    assert peek.clear_m((0.0, -20.0), (0.0, 20.0)) == pytest.approx(25.0, abs=0.6)
    assert peek.clear_m((0.0, 0.0), (40.0, 0.0)) == 0.0  # a way through it
    assert peek.clear_m((0.0, 80.0)) == 0.0  # beyond the frame: nothing known


def _unseen(record: Path) -> list[tuple[float, float, float]]:
    """Where the vehicle flew below the ceiling over ground no photo straight down (the
    higher overview, or a peek) showed within 2 m."""
    frames: list[CameraPose] = []
    ceiling = math.inf
    out = []
    with RecordingReader(record) as reader:
        for entry in reader.entries([OBSERVATIONS]):
            data = entry.value.payload if isinstance(entry.value, JsonDocument) else {}
            if data.get("type") == "Photo" and (
                data["tag"] == "overview-2" or data["tag"].startswith("peek")
            ):
                p = data["pose"]
                frames.append(CameraPose(tuple(p["pos_enu_m"]), p["heading_deg"], p["pitch_deg"]))
                if data["tag"] == "overview-2":
                    ceiling = p["pos_enu_m"][2]
            elif data.get("type") == "Telemetry" and frames and not data["landed"]:
                x, y, z = data["pos_enu_m"]
                if z < ceiling - 2.0 and not any(_shown(pose, x, y) for pose in frames):
                    out.append((x, y, z))
    return out


def _shown(pose: CameraPose, x: float, y: float) -> bool:
    ring = [(x + 2.0 * math.cos(a), y + 2.0 * math.sin(a), 0.0) for a in np.arange(0, 6.28, 0.8)]
    u, v, depth = project(np.array(ring), pose, K).T
    return bool(np.all(depth > 0) and np.all((u >= 0) & (u <= 639) & (v >= 0) & (v <= 479)))


@pytest.mark.parametrize("scene", ["town-10264.yaml", "town-10245.yaml"])
def test_side_cameras_stand_only_over_ground_seen_from_above(tmp_path: Path, scene: str) -> None:
    """Towers near the overview's edge: their side cameras stood 60-100 m out, beyond its
    frame, where a building would never have been seen. They peek first now, and the
    models are still built."""
    record = tmp_path / "f.mcap"
    summary = fly(FlyConfig(scene=str(DATA / scene), record=record))
    assert summary.evaluation.model_iou is not None
    assert _unseen(record) == []


class _GoBeyond(SearchMission):
    """Flies only one way: to 15 m over (40, 0), beyond a made-up overview's ground (a
    40 m square round home), with the ceiling at 60 m."""

    def fly(self) -> Wait[str]:
        yield from self.arm_and_take_off(30.0)
        self.ceiling_m = 60.0
        self.seen_ground = ((-20.0, -20.0), (20.0, -20.0), (20.0, 20.0), (-20.0, 20.0))
        yield from self.travel((40.0, 0.0, 15.0), None, 30.0, "place beyond")
        return "there"


@pytest.mark.parametrize(("building", "descends"), [((-40.0, 30.0), True), ((44.0, 0.0), False)])
def test_travel_looks_down_before_descending_beyond_the_seen_ground(
    building: tuple[float, float], descends: bool
) -> None:
    """Below the ceiling beyond the overview's ground the vehicle first looks straight down
    from the ceiling; with a building 2 m from the place (a 4 m square 4 m east of it) it
    stays at the ceiling over it, with none near it descends."""
    scene = _scene([(building[0], building[1], 2.0, 10.0)])
    mission = _GoBeyond(Params(), MissionInputs(target_rgb(scene)))
    flight = run(mission, FakeVehicle(scene)).outputs
    assert [o.tag for o in flight if isinstance(o, TakePhoto)] == ["peek-1"]
    targets = [o.pos_enu_m for o in flight if isinstance(o, GoTo)]
    assert ((40.0, 0.0, 15.0) in targets) is descends
    assert ((40.0, 0.0, 60.0) in targets) is True


@pytest.mark.parametrize("top_m", [3.0, 8.0, 20.0])
@pytest.mark.parametrize(
    "paint",
    [
        pytest.param((86, 87, 86), id="road-grey"),
        pytest.param((129, 115, 53), id="field-brown"),
        pytest.param((48, 128, 55), id="lawn-green"),
    ],
)
def test_a_peek_clears_the_ground_area_a_building_of_its_paint_stands_on_never_the_building(
    paint: tuple[int, int, int], top_m: float
) -> None:
    """A building painted as the ground area it stands at the edge of (a grey block on a
    road, a brown one on a field, a green one on a lawn), one storey to 20 m: in a look down
    from the ceiling they are one region of one colour. Parallax against photos from the
    ceiling elsewhere clears a part of one colour only as a whole (`standing_regions`): the
    building stays, with the area joined to it, and no place within the safety margin of
    its walls is clear. (Weighed as a whole by `on_ground` alone, the one-storey blocks
    were cleared with their areas: `stands_out` finds their patch.)"""
    rgb = list(paint)
    scene = scene_from_dict(
        {
            "target": "red",
            "ground": {
                "color": [118, 90, 66] if paint[1] > paint[0] + 40 else [56, 93, 50],
                "areas": [{"name": "area", "color": rgb,
                           "polygon": [[-50, -20], [50, -20], [50, -4], [-50, -4]]}],
                "texture": {"kind": "grain", "amplitude_dn": 8.0, "scale_m": 0.4, "seed": 5},
            },
            "buildings": [
                {"name": "red", "color": [210, 40, 40],
                 "blocks": [{"footprint": [[30, 30], [40, 30], [40, 38], [30, 38]], "top_m": 8}]},
                {"name": "block", "color": rgb,
                 "blocks": [{"footprint": [[-6, -4], [6, -4], [6, 4], [-6, 4]], "top_m": top_m}]},
            ],
        }
    )  # fmt: skip

    def photo(tag: str, x: float, y: float) -> Photo:
        pose = CameraPose((x, y, 117.0), 0.0, -90.0)
        return Photo(0, 0, tag, 0, pose, K, render(scene, pose, K))

    look = photo("peek-1", 10.0, 12.0)
    others = [photo("overview-2", -30.0, 40.0), photo("measure-1", 40.0, -30.0), photo("m", 0, 0)]
    m = SearchMission(Params(), MissionInputs(look.image_rgb))
    peek = Peek.of(look, m.params.vectorize, standing_regions(m, look, others))
    assert peek is not None
    margin = m.params.viewpoints.safety_margin_m
    for x, y in [(0.0, 0.0), (-6.0 - margin / 2, 0.0), (0.0, 4.0 + margin / 2), (6.5, 4.5)]:
        assert peek.clear_m((x, y)) < margin, (x, y)
