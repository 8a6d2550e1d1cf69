"""Stepped towers whose tiers share one colour. From above, such a tower's outline is its
lowest tier's; its upper tiers show only as walls inside that outline. Measured as one flat
roof it looks as low as its lowest tier, and a look or a top photo aimed over it descended
into the upper tiers (crashes in town scenes). A wall inside the outline shows a higher
part, at least as high as the wall's perspective says: such a roof counts as unknown. A
courtyard's far wall looks alike, but where it stands the other photo shows the ground."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from shapely.geometry import Point, Polygon  # type: ignore[import-untyped]

from tests.mission.scenes import on_grey_ground
from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission import MissionInputs, SearchMission, Status
from uavtool.mission.analysis import NOT_FLAT_M, nadir_shapes, not_flat, roof_between
from uavtool.mission.observations import Photo
from uavtool.mission.params import Params
from uavtool.mission.unknown import (
    Known,
    Overview,
    Unknown,
    evidence,
    footprint_at,
    region_of,
    unexplained,
    unknown_place,
    unknown_roof,
)
from uavtool.nav.heights import higher_part_m
from uavtool.recording import JsonDocument, RecordingReader
from uavtool.recording.topics import OBSERVATIONS
from uavtool.runner.evaluate import closest_clearance
from uavtool.runner.fly import FlyConfig, fly
from uavtool.sitl import SitlConfig
from uavtool.vision import Shape
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import inner_walls, not_ground_regions
from uavtool.world import Scene, load_scene, render, scene_from_dict, scene_to_dict

DATA = Path(__file__).parent / "data"
K = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)


def _block(ring: list[tuple[float, float]], base_m: float, top_m: float) -> dict[str, Any]:
    return {"footprint": [list(p) for p in ring], "base_m": base_m, "top_m": top_m}


def _square(cx: float, cy: float, half: float) -> list[tuple[float, float]]:
    return [
        (cx - half, cy - half),
        (cx + half, cy - half),
        (cx + half, cy + half),
        (cx - half, cy + half),
    ]


def _scene() -> Scene:
    """A flat block and a block with a courtyard (four wings round a yard)."""
    yard_outer = _square(-20.0, 15.0, 6.0)
    return on_grey_ground(
        "tiers",
        "flat",
        [
            {
                "name": "flat",
                "color": [54, 125, 217],
                "blocks": [_block(_square(20.0, 20.0, 4.0), 0.0, 12.0)],
            },
            {
                "name": "yard",
                "color": [217, 54, 162],
                "blocks": [
                    _block([*yard_outer[:2], (-14.0, 12.5), (-26.0, 12.5)], 0.0, 15.0),
                    _block([(-26.0, 17.5), (-14.0, 17.5), *yard_outer[2:]], 0.0, 15.0),
                    _block([(-26.0, 12.5), (-22.5, 12.5), (-22.5, 17.5), (-26.0, 17.5)], 0.0, 15.0),
                    _block([(-17.5, 12.5), (-14.0, 12.5), (-14.0, 17.5), (-17.5, 17.5)], 0.0, 15.0),
                ],
            },
        ],
    )


def _photo(
    scene: Scene, x: float, y: float, alt: float, index: int, heading_deg: float = 0.0
) -> Photo:
    pose = CameraPose((x, y, alt), heading_deg, -90.0)
    return Photo(index, index, f"photo-{index}", 0, pose, K, render(scene, pose, K))


def _shape(photo: Photo, rgb: tuple[int, int, int]) -> Shape:
    shapes = nadir_shapes(Params(), photo.image_rgb)
    near = [
        s for s in shapes if max(abs(a - b) for a, b in zip(s.colour_rgb, rgb, strict=True)) < 40
    ]
    assert near, f"no shape of colour {rgb} in the photo"
    return max(near, key=lambda s: s.area_px)


@pytest.fixture(scope="module")
def photos() -> tuple[Photo, Photo]:
    scene = _scene()
    return _photo(scene, 0.0, 0.0, 117.0, 0), _photo(scene, 8.0, -6.0, 117.0, 1)


@pytest.mark.parametrize("heading_deg", [270.0, 0.0, 45.0])
def test_a_stepped_tower_is_not_one_flat_roof(heading_deg: float) -> None:
    """Tower b04 of town scene 5160: tiers of one colour 20.1, 33.8 and 43.0 m up, beside
    home. Photographed from 117 m over home and over the tower, its outline (the lowest
    tier's) was measured as one flat roof 22.6-23.2 m up, and a look descended into the top
    tier."""
    scene = load_scene(DATA / "town-5160.yaml")
    home = _photo(scene, 0.0, 0.0, 117.2, 0, heading_deg)
    over = _photo(scene, 0.8, -5.17, 117.2, 1, heading_deg)
    a, b = _shape(home, (190, 217, 54)), _shape(over, (190, 217, 54))
    walls = inner_walls(home.image_rgb, a)
    assert walls  # between the tiers, seen from 5 m off
    top = higher_part_m(walls, home.pose, home.intrinsics, roof_m=20.1)
    assert top is not None and 20.1 + NOT_FLAT_M < top <= 43.0  # a least height: at most the top
    assert not_flat(a, home, 20.1, over)
    assert roof_between(a, home, b, over) is None  # unknown, not 23 m


@pytest.mark.parametrize(("rgb", "roof_m"), [((54, 125, 217), 12.0), ((217, 54, 162), 15.0)])
def test_flat_roofs_and_courtyards_are_measured(
    photos: tuple[Photo, Photo], rgb: tuple[int, int, int], roof_m: float
) -> None:
    """A courtyard's walls go down to the ground, which shows between them: they are not a
    higher part of the roof."""
    home, over = photos
    roof = roof_between(_shape(home, rgb), home, _shape(over, rgb), over)
    assert roof is not None and abs(roof - roof_m) < 2.5


@pytest.mark.parametrize("seed", [5160, 5325, 7119, 7156, 7363])
def test_town_scenes_with_towers_end_without_a_crash(seed: int) -> None:
    """Collisions in town scenes (`uavtool scene random --hard --town --random-home --seed
    N`). 5160 and 7119: home beside a three-tier tower of one colour that is itself a point
    of interest; 5325: the target is such a tower, its tiers found apart; 7363: the way home
    descended beside such a tower; 7156: a 43 m tower of unknown height, its roof's outline
    nearer home than a 25 m roof's would be, met on the way to the diagonal photo.
    No building but the target is reported found. 5325's target, matched by score alone
    while another of its colour scored 0.615 from as far, was not reported found for a
    while: a score from afar says little of a building of several heights (world 50196).
    Now the other, photographed as the target picture was, shows no higher part where the
    picture shows one, and the target is found (`test_higher_part.py`)."""
    summary = fly(FlyConfig(scene=str(DATA / f"town-{seed}.yaml"), no_record=True))
    assert summary.outcome.status is not Status.CRASHED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def test_a_courtyard_whose_ground_is_hidden_is_still_one_flat_roof() -> None:
    """Town scene 1035: the decoy b07 is the target's T with a courtyard. From the overview
    the yard shows only its far wall, inside the roof's outline like a tier's wall; taken for
    a higher part, the decoy's roof stayed unknown, it was judged from 117 m where the yard
    does not show, and it outscored the target. Over it, the other photo shows the yard's
    ground where the wall seemed to stand."""
    summary = fly(FlyConfig(scene=str(DATA / "town-1035.yaml"), no_record=True))
    assert summary.evaluation.matched_building == "b05" == summary.evaluation.target_building


def _tower_photos() -> tuple[Photo, Photo, Shape]:
    """A 40 m tower 30 m east of home, photographed from 117 m over home and over it, and
    its roof in the photo over home."""
    tower = {
        "name": "tower",
        "color": [54, 160, 217],
        "blocks": [_block(_square(30.0, 0.0, 4.0), 0.0, 40.0)],
    }
    data = scene_to_dict(_scene())
    data["buildings"] = [tower]
    data["target"] = "tower"
    scene = scene_from_dict(data)
    home = _photo(scene, 0.0, 0.0, 117.0, 0)
    return home, _photo(scene, 30.0, 0.0, 117.0, 1), _shape(home, (54, 160, 217))


def test_where_a_roof_of_unknown_height_may_stand() -> None:
    """A 40 m tower 30 m east of home, its roof unmeasured: from 117 m over home its outline
    could be a roof anywhere from the ground up to just below the camera, so its building
    anywhere from 30 m out to nearly over home (a 25 m guess left out where it stands). A
    photo over the tower, from the same altitude, sees the ground where the taller and the
    lower roofs would stand: what remains holds the tower and no longer reaches home."""
    home, over, shape = _tower_photos()
    wide = Polygon(unknown_roof(shape, home, 111.0).footprint)
    narrow = Polygon(unknown_roof(shape, home, 111.0, (over,)).footprint)
    true = Polygon(_square(30.0, 0.0, 4.0))
    assert wide.distance(Point(0.0, 0.0)) < 3.0  # up to 111 m: nearly over home
    low = Polygon(unknown_roof(shape, home, 25.0).footprint)
    assert low.intersection(true).area < 0.5 * true.area
    assert narrow.intersection(true).area > 0.9 * true.area  # the tower stays in
    assert narrow.distance(Point(0.0, 0.0)) > 15.0  # but home is clear of it


def test_the_highest_a_roof_of_unknown_height_may_be() -> None:
    """The same tower, 40 m tall: with nothing but the photo over home, its roof may be up
    to just below the camera; the photo over it sees the ground where the taller roofs'
    buildings would stand, so what is left is bounded — above the true 40 m (a bound that
    cuts a real roof would fly into it), and well below the camera."""
    home, over, shape = _tower_photos()
    assert unknown_roof(shape, home, 111.0).upper_m == 111.0
    upper = unknown_roof(shape, home, 111.0, (over,)).upper_m
    assert 40.0 <= upper <= 60.0  # 56 m here: the 2 m planes up to 54 m are left


def test_over_any_one_place_only_the_heights_that_put_the_building_there_count() -> None:
    """The same 40 m tower, seen only from over home (117 m): placed higher, its roof's
    outline slides toward home, from 45.6 m out (on the ground) to nearly over home (just
    below the camera). Over any one place only the heights that put the building there
    count: never less than the true 40 m where it stands, a low one only where a low one
    would stand, the highest nearest home, none beyond it."""
    home, _over, shape = _tower_photos()
    place = unknown_roof(shape, home, 111.0)
    assert place.upper_m == 111.0

    def top(x: float) -> float | None:
        return place.top_m(lambda ring: Polygon(ring).distance(Point(x, 0.0)) <= 1.0)

    assert 40.0 <= (top(30.0) or 0.0) <= 60.0  # at 60 m it would stand 22 m out, no nearer
    assert (top(46.0) or math.inf) <= 20.0  # where only a low one would stand
    tops = [top(x) for x in (46.0, 40.0, 30.0, 20.0, 10.0, 2.0)]
    assert all(t is not None for t in tops)
    assert tops == sorted(tops)  # type: ignore[type-var]
    assert tops[-1] == 111.0
    assert top(-5.0) is None  # past home: nowhere


def _tower_on_a_wing() -> Scene:
    """A 14 m wing with a 50 m tower rising from it, 45 m east of home."""
    building = {
        "name": "tower",
        "color": [54, 160, 217],
        "blocks": [
            _block([(41.0, -6.0), (49.0, -6.0), (49.0, 0.0), (41.0, 0.0)], 0.0, 14.0),
            _block(_square(46.5, -2.0, 2.0), 14.0, 50.0),
        ],
    }
    data = scene_to_dict(_scene())
    data["buildings"] = [building]
    data["target"] = "tower"
    return scene_from_dict(data)


def test_a_roof_whose_building_reaches_past_the_frame_may_be_as_high_as_any() -> None:
    """A 14 m block with a 50 m tower rising from it, 45 m east of home: from 117 m over
    home the block's roof is whole in the photo, the tower's top beyond the frame, its walls
    joining the block's roof to the frame's edge. A photo over the wing sees the ground where the
    wing's roof would put a taller building, so the roof alone is bounded low; but what
    stands around it reaches past the frame, where a higher roof may be: the building is
    as high as anything below the camera may be. (Bounded by its roof alone, a look at the
    tower's wing once passed 0.08 m from the tower.)"""
    scene = _tower_on_a_wing()
    home = _photo(scene, 0.0, 0.0, 117.0, 0)
    over = _photo(scene, 45.0, -3.0, 117.0, 1)
    wing = _shape(home, (54, 160, 217))
    assert not wing.cut_by_border
    regions = not_ground_regions(home.image_rgb)
    assert unknown_roof(wing, home, 111.0, (over,)).upper_m < 50.0
    assert unknown_place(wing, home, 111.0, (over,), regions).upper_m == 111.0


def test_a_taller_part_whose_roof_is_beyond_the_frame_is_not_explained_by_the_wing() -> None:
    """Town scene 9854: a stepped tower of one colour, its top tier's roof beyond the frame of
    the photo over home and its walls rising from the lower tier's roof to the frame's edge.
    The lower tier was measured (22.8 m) and nothing else was known of the building: a look
    at it descended to 42 m beside the 48.6 m top tier (0.51 m). The walls are no part of the
    wing as measured: they are a building of unknown height, as high as anything may be."""
    home = _photo(_tower_on_a_wing(), 0.0, 0.0, 117.0, 0)
    wing = _shape(home, (54, 160, 217))
    regions = not_ground_regions(home.image_rgb)
    rest = unexplained(home, (wing,), (14.0,), (True,), regions, VectorizeParams())
    assert len(rest) == 1
    assert unknown_place(rest[0], home, 111.0, (), regions).upper_m == 111.0
    # Of unknown height, the wing explains its whole region: nothing is left.
    assert unexplained(home, (wing,), (25.0,), (False,), regions, VectorizeParams()) == []


def test_a_wing_measured_late_leaves_its_tower_as_high_as_anything_may_be() -> None:
    """The wing of the test before, its roof of unknown height after the survey: it may stand
    anywhere in its region, walls and all, up to 111 m. A look measures it later (14 m): the
    walls it does not explain stand where they are, of unknown height. Measuring the wing
    once dropped the whole region from what may stand high, and a closer look could have
    descended beside the tower."""
    home = _photo(_tower_on_a_wing(), 0.0, 0.0, 117.0, 0)
    wing = _shape(home, (54, 160, 217))
    regions = tuple(not_ground_regions(home.image_rgb))

    def place_of(shape: Shape) -> Unknown:
        return unknown_place(shape, home, 111.0, (), regions)

    m = SearchMission(Params(), MissionInputs(np.asarray(render(_scene(), home.pose, K))))
    m.ceiling_m = 117.0
    m.overview = Overview(home, (wing,), [None], regions, place_of, VectorizeParams())
    m.unknown = {0: place_of(wing)}
    tower = (46.5, -2.0)
    high = m.floor_at(*tower)
    assert high > 111.0  # over the highest a building there may be, by the margin
    m.learn_roof(0, footprint_at(wing, home, 14.0), 14.0)
    assert 0 not in m.unknown and m.overview.roofs_m == [14.0]
    assert [place.upper_m for place in m.unknown.values()] == [111.0]
    assert m.floor_at(*tower) == high  # the tower's walls still count
    # had the wing's roof been all its region held, the floor over the tower would be 14 m
    # and the margin
    m.unknown = {}
    assert m.floor_at(*tower) < 30.0


def test_buildings_measured_right_explain_all_they_show(photos: tuple[Photo, Photo]) -> None:
    """A flat block and a courtyard block, measured: their roofs and walls are all that is
    not ground."""
    home, _ = photos
    flat, yard = _shape(home, (54, 125, 217)), _shape(home, (217, 54, 162))
    regions = not_ground_regions(home.image_rgb)
    shapes, measured = (flat, yard), (True, True)
    assert unexplained(home, shapes, (12.0, 15.0), measured, regions, VectorizeParams()) == []


def test_a_roof_is_in_the_region_it_merges_with() -> None:
    """Town scene 10043, from 117.2 m over home: a 6.6 m box touches a 41 m block of another
    colour in the photo. The box's corners lie on the outline of the region both make, some
    just outside once both outlines are simplified, and its region was not found by them:
    what stood around it was left out of where it may stand (so were four other roofs' of
    the thirteen, the target's among them). The roof's inside tells."""
    scene = load_scene(DATA / "town-10043.yaml")
    home = _photo(scene, 0.0, 0.0, 117.195, 0, 90.0)
    regions = not_ground_regions(home.image_rgb)
    box, block = _shape(home, (163, 204, 51)), _shape(home, (61, 204, 51))
    assert region_of(box, regions) is region_of(block, regions) is not None
    assert all(region_of(s, regions) is not None for s in nadir_shapes(Params(), home.image_rgb))


def test_a_look_keeps_clear_of_a_taller_tier_beyond_the_frame(tmp_path: Path) -> None:
    """Town scene 9854 (see the test before): the look at the stepped tower b03, measured by
    its lower tier, passed 0.51 m from its top tier. Away from the take-off column (home
    stands beside a 48.6 m tower) every pass keeps the safety margin."""
    record = tmp_path / "f.mcap"
    summary = fly(FlyConfig(scene=str(DATA / "town-9854.yaml"), record=record))
    # The 48.6 m stepped target is matched from far above, or honestly not at all (which of
    # the two turns on tenths of a metre in where the photos were taken); never wrongly.
    assert summary.outcome.status in (Status.COMPLETED, Status.NO_MATCH), summary.outcome.reason
    assert summary.evaluation.matched_building in ("", summary.evaluation.target_building)
    route = []
    with RecordingReader(record) as reader:
        for entry in reader.entries([OBSERVATIONS]):
            data = entry.value.payload if isinstance(entry.value, JsonDocument) else {}
            if data.get("type") == "Telemetry" and not data["landed"]:
                x, y, z = data["pos_enu_m"]
                if math.hypot(x, y) > 1.5:
                    route.append((x, y, z))
    scene = load_scene(DATA / "town-9854.yaml")
    clearance, name = closest_clearance(route, scene, body_radius_m=SitlConfig().body_radius_m)
    assert clearance >= Params().viewpoints.safety_margin_m, name


def test_a_lower_roof_seen_beneath_rules_heights_out() -> None:
    """A 10 m block of unknown height 57 m out from home, photographed from 117 m over home
    and over a 12 m block measured between them: from home, taller and taller roofs of the
    first block's outline would stand nearer home, over the 12 m block, where the other
    photo sees no ground (the 12 m roof covers it), so those heights stood (92 m). But it
    sees the 12 m roof, of another colour, in their place: nothing taller stands there.
    With that evidence the bound comes down (44 m) and stays above the true 10 m. A known
    roof of the block's own colour could be a lower tier of it: it is no evidence."""
    data = scene_to_dict(_scene())
    data["buildings"] = [
        {
            "name": "low",
            "color": [54, 125, 217],
            "blocks": [_block(_square(20.0, 20.0, 10.0), 0.0, 12.0)],
        },
        {
            "name": "out",
            "color": [217, 125, 54],
            "blocks": [_block(_square(40.0, 40.0, 4.0), 0.0, 10.0)],
        },
    ]
    data["target"] = "out"
    scene = scene_from_dict(data)
    home, over = _photo(scene, 0.0, 0.0, 117.0, 0), _photo(scene, 10.0, 10.0, 117.0, 1)
    shape = _shape(home, (217, 125, 54))
    low = Known(tuple(_square(20.0, 20.0, 10.0)), 12.0, _shape(home, (54, 125, 217)).colour_rgb)
    alone = unknown_roof(shape, home, 111.0, (over,)).upper_m
    seen = evidence(over, (low,), tolerance_dn=10.0)
    upper = unknown_roof(shape, home, 111.0, (seen,), hue_tolerance_deg=12.0).upper_m
    assert 10.0 <= upper < alone - 10.0
    own = evidence(over, (low._replace(colour_rgb=shape.colour_rgb),), tolerance_dn=10.0)
    assert unknown_roof(shape, home, 111.0, (own,), hue_tolerance_deg=12.0).upper_m == alone
