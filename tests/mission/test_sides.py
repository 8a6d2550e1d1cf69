"""Side photos: which edges a silhouette touches, and a building taller than it looked."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.mission.scenes import DATA, fly_data_scene
from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.mission import Status
from uavtool.mission.observations import Photo
from uavtool.mission.sides import _in_line
from uavtool.nav import Rect
from uavtool.runner.fly import FlyConfig, fly
from uavtool.vision import Shape
from uavtool.vision.shapes import cut_edges
from uavtool.world import load_scene, scene_from_dict, scene_to_dict
from uavtool.world.scene import dump_scene

K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)


def _box(u0: float, v0: float, u1: float, v1: float) -> Shape:
    ring = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]], dtype=np.float64)
    touches = u0 <= 1.0 or v0 <= 1.0 or u1 >= 638.0 or v1 >= 478.0
    return Shape.from_rings(colour_rgb=(200, 40, 40), polygon_px=ring, cut_by_border=touches)


def test_cut_edges() -> None:
    assert cut_edges((_box(100, 50, 500, 400),), K) == set()
    assert cut_edges((_box(100, 0, 500, 400),), K) == {"top"}
    assert cut_edges((_box(0, 0, 500, 479),), K) == {"top", "left", "bottom"}
    assert cut_edges((_box(100, 50, 639, 400), _box(10, 0, 60, 80)), K) == {"right", "top"}


def test_a_stepped_tower_taller_than_its_outline_is_photographed_whole() -> None:
    """In `tall-spread`, red is a 24 m tower of three L-shaped tiers; seen from above its
    outline is its lowest tier's, 7.8 m up. The front photo, planned for that, cuts the tower's
    top: the mission plans it again for a taller building from the same side, and the right
    photo is planned for that height before it is flown. The model is built."""
    summary = fly(FlyConfig(scene="tall-spread", no_record=True))
    o, e = summary.outcome, summary.evaluation
    assert o.status is Status.COMPLETED, o.reason
    assert e.matched_building == "red" and o.model_built
    assert e.model_iou is not None and e.model_iou > 0.55
    assert summary.clearance_m is not None and summary.clearance_m > 4.0


def test_a_tower_merged_with_one_behind_it_is_cut_back_to_where_it_stands() -> None:
    """A camera looking down from 60 m, 40 m south of a 10 m square tower 30 m tall: the
    tower stands in the box its footprint and height project to. A tower of its colour
    behind it shows above it in the photo, merged into one outline cut by the frame's top.
    With the height measured, the silhouette is cut back to the box and touches no edge
    (no other building's top to chase); with the height only assumed, it stays as seen.
    A neighbour of the colour beside the box, mostly out of it, is no part of it."""
    rect = Rect((0.0, 0.0), 0.0, 10.0, 10.0)
    pose = CameraPose((0.0, -45.0, 60.0), 0.0, -40.0)
    photo = Photo(0, 0, "front", 0, pose, K, np.zeros((480, 640, 3), np.uint8))
    box = project(np.array([(x, y, z) for z in (0.0, 30.0) for x, y in rect.corners()]), pose, K)
    u0, v0 = box[:, 0].min(), box[:, 1].min()
    u1, v1 = box[:, 0].max(), box[:, 1].max()
    merged = _box(u0 + 5, 0, u1 - 5, v1 - 5)  # the tower and the one behind, up to the top
    beside = _box(5, v0 + 10, u0 - 5, v1)
    assert merged.cut_by_border
    (kept,) = _in_line((merged, beside), rect, photo, 30.0)
    assert kept is merged
    (cut,) = _in_line((merged, beside), rect, photo, 30.0, clip=True)
    assert not cut.cut_by_border and cut_edges((cut,), K) == set()
    assert cut.polygon_px[:, 1].min() > v0 - 0.11 * max(u1 - u0, v1 - v0) - 1.0


def test_a_road_a_look_down_shows_beside_a_viewpoint_is_no_building() -> None:
    """World scene 50293: both side viewpoints lie beyond the ground the overview saw, and
    the looks down from the ceiling show a grey region 2.4 m from one: road1 and road3,
    which parallax against the photos from the ceiling tells lie on the ground. (Taken for
    buildings, they had the side planned again around them, from elsewhere.) Both photos
    are taken where planned, and the model is built."""
    summary, events = fly_data_scene("world-50293")
    for side in ("front", "right"):
        assert f"{side} viewpoint: beyond the overview's ground; no building near it below" in (
            events
        )
    assert not any("planned again" in e for e in events), events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def test_a_side_photo_that_does_not_show_the_building_is_taken_again_from_elsewhere() -> None:
    """World scene 50327: the front photo showed nothing of the target's colour where the
    target stands: a building between, inside a region of unknown height that holds the
    target too (so no sight line was planned around it). The model was not built ("front:
    no silhouette of the object in the photo"). No sight line along that one: the front is
    planned again from elsewhere, and the model is built."""
    summary, events = fly_data_scene("world-50327")
    assert (
        "front photo: the building does not show where it stands; something stands between"
        in events
    )
    assert "front viewpoint: planned again with no sight line along that one" in events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def test_a_field_the_tour_measured_on_the_ground_is_cleared_by_a_look_down() -> None:
    """World scene 50157: the front viewpoint lies beyond the overview's ground, over a
    field the tour measured on the ground (0 m). As a "measured roof" it always stood in
    the look down from the ceiling, and hid the ground in the other photos: the front was
    refused twice, and the flight ended found, no front photo. Ground is no roof: the look
    clears the field, the photo is taken and the model built."""
    summary, events = fly_data_scene("world-50157")
    assert "front viewpoint: beyond the overview's ground; no building near it below" in events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def test_a_building_a_look_down_shows_beside_a_viewpoint_is_planned_around(
    tmp_path: Path,
) -> None:
    """World scene 50157 with a 6 m shed 2.4 m from the front viewpoint, beyond the
    overview's frame: no photo from above showed it before the look down from the ceiling
    over the viewpoint. The look shows it: the vehicle does not descend there, the front
    is planned again around what the look showed, and taken from elsewhere."""
    scene = scene_to_dict(load_scene(str(DATA / "world-50157.yaml")))
    shed = [[14.0, 49.5], [17.0, 49.5], [17.0, 52.5], [14.0, 52.5]]
    scene["buildings"].append(
        {"name": "shed", "color": [140, 60, 200], "blocks": [{"footprint": shed, "top_m": 6.0}]}
    )
    path = tmp_path / "shed.yaml"
    path.write_text(dump_scene(scene_from_dict(scene)))
    events: list[str] = []
    config = FlyConfig(scene=str(path), no_record=True)
    summary = fly(config, progress=lambda e, _t: events.append(e))
    refused = "front viewpoint: beyond the overview's ground, and a building may stand 2.4 m"
    assert any(e.startswith(refused) for e in events), events
    assert any("front viewpoint: planned again around the" in e for e in events), events
    assert any(e.startswith("front viewpoint: turned") for e in events), events
    assert summary.outcome.status in (Status.COMPLETED, Status.PARTIAL), summary.outcome.reason
    assert "no front" not in summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def test_a_side_that_only_its_roof_line_shows_over_its_neighbours_is_photographed() -> None:
    """World scene 50102: the target (b03, a 22.8 m courtyard L) stands among neighbours as
    tall as it (22.8 m) and others whose height no photo measured. From no side does a
    camera within the pitch limit see the upper half of its walls over them, and the flight
    ended without a right photo, so without a model. The model carves nothing below what a
    side photo sees of the building: a camera that sees its roof line over the neighbours
    is planned last, and the model is built (IoU 0.99 here)."""
    summary, events = fly_data_scene("world-50102")
    o, e = summary.outcome, summary.evaluation
    assert o.status is Status.COMPLETED, o.reason
    assert e.matched_building == e.target_building == "b03"
    assert any(
        ev.startswith("right viewpoint:") and ev.endswith("over its neighbours to its roof line")
        for ev in events
    ), events
    assert "right photo: the building's foot is hidden behind its neighbours" in events
    assert e.model_iou is not None and e.model_iou > 0.9
    assert summary.clearance_m is not None and summary.clearance_m > 4.0
