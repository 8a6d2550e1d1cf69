"""Ground that is not one grey: a ground of a colour, lawns, roads and car parks, a painted
copy of the target on the ground. None is a building, a point of interest or an obstacle:
parallax between photos from above tells them (`uavtool.nav.parallax`)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from tests.mission.driver import fly
from tests.mission.scenes import fly_data_scene
from uavtool.camera import CameraPose, Intrinsics, project
from uavtool.mission import MissionInputs, Params, Photo, SearchMission, Status
from uavtool.mission.analysis import nadir_shapes
from uavtool.mission.ground import lies_on_ground, regions_off_ground, standing_regions
from uavtool.mission.peek import Peek
from uavtool.mission.unknown import region_of, unexplained
from uavtool.runner.fly import FlyConfig
from uavtool.runner.fly import fly as fly_scene
from uavtool.vision.params import VectorizeParams
from uavtool.vision.vectorize import not_ground_regions
from uavtool.world import Scene, load_scene, render, scene_from_dict
from uavtool.world.ground import GroundArea, GroundTexture, TextureKind
from uavtool.world.scene import dump_scene

RED_L = ((5.0, -12.0), (15.0, -12.0), (15.0, -4.0), (11.5, -4.0), (11.5, -8.5), (5.0, -8.5))
"""The paper target's footprint from above."""


def _fly(tmp_path: Path, **changes: object) -> tuple[object, list[str]]:
    scene = tmp_path / "scene.yaml"
    scene.write_text(dump_scene(dataclasses.replace(load_scene("paper"), **changes)))
    events: list[str] = []
    summary = fly_scene(
        FlyConfig(scene=str(scene), no_record=True), progress=lambda e, _t: events.append(e)
    )
    return summary, events


def test_a_copy_of_the_target_painted_on_the_ground_is_not_taken_for_it(tmp_path: Path) -> None:
    """The target's L in the target's red, painted on a brown ground with a grain, 25 m west
    of the real one: it matches the target picture perfectly by shape and colour, and it is
    flat. The real building is found; the painting is ground."""
    painted = tuple((x - 35.0, y - 2.0) for x, y in RED_L)
    summary, events = _fly(
        tmp_path,
        ground_rgb=(125, 85, 59),
        ground_areas=(GroundArea("painted", (210, 40, 40), painted),),
        ground_texture=GroundTexture(TextureKind.GRAIN, 6.0, 0.3, 7),
    )
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason  # type: ignore[attr-defined]
    assert summary.evaluation.matched_building == "red"  # type: ignore[attr-defined]
    assert any("lie on the ground" in e for e in events), events


def test_a_green_roof_on_grass_is_found(tmp_path: Path) -> None:
    """The issue's green ground (86, 125, 62) and a green target (40, 150, 50): the grass is
    no building and no point of interest, and the target's roof is told from it."""
    paper = load_scene("paper")
    buildings = tuple(
        dataclasses.replace(b, color_rgb=(40, 150, 50)) if b.name == "red" else b
        for b in paper.buildings
    )
    summary, _ = _fly(tmp_path, buildings=buildings, ground_rgb=(86, 125, 62))
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason  # type: ignore[attr-defined]
    assert summary.evaluation.matched_building == "red"  # type: ignore[attr-defined]


def test_a_tower_a_lawn_of_unknown_height_explained_stays_an_obstacle_once_it_is_ground() -> None:
    """World scene 50391: a 16.8 m stepped tower (b00, green) stands beside a green lawn.
    In the overview the tower, the lawn and the roads are one region, and the vectorizer
    kept only the lawn: of unknown height, it explained the whole region, tower included.
    The tour's photos then showed the lawn is ground, and the tower was in no obstacle at
    all: the front viewpoint was planned 1.25 m from its wall. Ground explains only its own
    outline; what else its region holds stays an obstacle."""
    scene = load_scene(str(Path(__file__).parent / "data" / "world-50391.yaml"))
    tower = next(b for b in scene.buildings if b.name == "b00")
    top = max(block.top_m for block in tower.blocks)
    base = shapely.Polygon(tower.blocks[0].footprint_enu_m)
    flown = fly(scene)
    mission = flown.mission
    texts = flown.flight.texts()
    assert any("lie on the ground (parallax between the overview and" in t for t in texts)
    covered = [
        shapely.Polygon(ring).intersection(base).area / base.area
        for place in mission.unknown.values()
        for ring, high in (place.bands or ((place.footprint, place.upper_m),))
        if high >= top
    ] + [
        shapely.Polygon(ring).intersection(base).area / base.area
        for ring, roof in mission.roofs
        if roof >= top - 1.0
    ]
    assert max(covered, default=0.0) > 0.9


def test_the_ground_beside_a_darker_field_of_its_hue_is_ground() -> None:
    """World scene 50015: a brown ground with a grain, and a darker brown field beside the
    road. The ground, a region of its own colour as wide as the frame, lies on the ground
    by parallax, but the field along its outline looks like its walls (another shade of
    its colour): as long as it did, the ground stayed a building of unknown height under
    every way, looks flew at 116 m and small buildings of the target's colour were never
    judged. The field's own parallax shows it lies on the ground too, in a photo that sees
    it from elsewhere: no walls, and the ground is no obstacle. (Photographed here from
    where a flight's tour once took its photos: whether a flight has such a photo depends
    on which roofs its tour measures, and since the roofs' walls were told from them by the
    roof's own spread, the flight over this scene takes none that tells.)"""
    scene = load_scene(str(Path(__file__).parent / "data" / "world-50015.yaml"))
    params = Params()
    k = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)

    def photo(tag: str, x: float, y: float, z: float) -> Photo:
        pose = CameraPose((x, y, z), 270.0, -90.0)
        return Photo(0, 0, tag, 0, pose, k, render(scene, pose, k))

    high = photo("overview-2", 0.0, 0.0, 117.4)
    low = photo("overview", 0.0, 0.0, 45.1)
    aside = photo("measure-2", -48.0, -2.4, 117.4)
    ground = max(nadir_shapes(params, high.image_rgb), key=lambda s: s.area_px)
    assert ground.area_px > 640 * 480 / 2
    m = SimpleNamespace(params=params)
    assert not lies_on_ground(m, ground, high, (low,), one_colour=False)  # type: ignore[arg-type]
    assert lies_on_ground(m, ground, high, (low, aside), one_colour=False)  # type: ignore[arg-type]


def test_a_lawn_on_the_ground_is_no_part_of_the_building_on_it_but_its_neighbour_still_is() -> None:
    """A 12 m blue building stands on a lawn, and a 30 m grey tower (no building colour)
    touches the lawn's far edge: from 80 m they are one region of what is not ground. Of
    unknown height, the building may stand anywhere in its region: with the lawn, over the
    whole of it and up to the tower (world scene 50217: a car park, a lawn and a field held
    every look near a candidate 66 m up). Once the lawn lies on the ground, the building
    stands in its own part; the tower, in no building's part, is still what no roof
    explains (an obstacle), as it must be (`test_a_tower_a_lawn_...` above)."""
    scene = scene_from_dict(
        {
            "target": "blue",
            "ground": {
                "color": [107, 161, 195],
                "areas": [{"name": "lawn", "color": [48, 128, 55],
                           "polygon": [[-14, -8], [12, -8], [12, 8], [-14, 8]]}],
            },
            "buildings": [
                {"name": "blue", "color": [54, 84, 217],
                 "blocks": [{"footprint": [[-9, -3], [-3, -3], [-3, 3], [-9, 3]], "top_m": 12}]},
                {"name": "tower", "color": [128, 128, 128],
                 "blocks": [{"footprint": [[12, -2], [16, -2], [16, 2], [12, 2]], "top_m": 30}]},
            ],
        }
    )  # fmt: skip
    k = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)
    pose = CameraPose((0.0, 0.0, 80.0), 0.0, -90.0)
    photo = Photo(0, 0, "overview-2", 0, pose, k, render(scene, pose, k))
    shapes = nadir_shapes(Params(), photo.image_rgb)
    blue = next(s for s in shapes if s.colour_rgb[2] > 150 and s.colour_rgb[0] < 100)
    lawn = next(s for s in shapes if s.colour_rgb[1] > s.colour_rgb[0] + 40 and s is not blue)
    regions = not_ground_regions(photo.image_rgb)
    whole = region_of(blue, regions)
    assert whole is not None and region_of(lawn, regions) is whole
    m = SearchMission(Params(), MissionInputs(photo.image_rgb))
    parts = regions_off_ground(m, photo, regions, [lawn])
    own = region_of(blue, parts)
    assert own is not None and own.area_px < 0.5 * whole.area_px
    rest = unexplained(
        photo, (blue, lawn), (25.0, 0.0), (False, True), regions, VectorizeParams(), parts
    )
    top = project(np.array([(14.0, 0.0, 30.0)]), pose, k)[0, :2]
    assert any(shapely.Polygon(r.polygon_px).contains(shapely.Point(*top)) for r in rest)
    # ground that is no shape (cleared by parallax, `standing_regions`) is in no part, and
    # nothing it leaves unexplained: only the tower
    alone = unexplained(photo, (blue,), (25.0,), (False,), regions, VectorizeParams(), parts)
    grass = project(np.array([(4.0, 5.0, 0.0)]), pose, k)[0, :2]
    assert any(shapely.Polygon(r.polygon_px).contains(shapely.Point(*top)) for r in alone)
    assert not any(shapely.Polygon(r.polygon_px).contains(shapely.Point(*grass)) for r in alone)
    # the whole region, lawn and tower, was the building's before
    assert (
        unexplained(photo, (blue, lawn), (25.0, 0.0), (False, True), regions, VectorizeParams())
        == []
    )


def test_a_building_on_a_car_park_beside_a_lawn_is_looked_at_low_enough_to_judge() -> None:
    """World scene 50217: the target's mirror image (6.5 m, the target's colour) stands on
    a car park that touches a lawn and a field, all three on the ground by parallax, and a
    teal stepped building stands on the lawn. In the overview all of them are one region;
    of unknown height, the teal building might have stood anywhere in it, up to 66 m over
    the mirror image, whose look stayed at 70.6 m, where it was drawn too small to judge:
    the flight ended "which is the target is not known". The teal building stands in its
    own part of the region: the mirror image is looked at from over its roof and ruled
    out, and the target (b06) is found."""
    summary, events = fly_data_scene("world-50217")
    assert any("the target's mirror image" in e for e in events), events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b06"


def test_a_lawn_found_on_the_ground_leaves_room_for_the_side_photos() -> None:
    """World scene 50007: its green ground (109, 151, 78) is a shape of a building colour
    covering the whole overview, of unknown height until the tour's photos tell it lies
    on the ground. Kept as an obstacle of height 0 (and, cut by the frame, swept past it),
    it stood within the safety margin of every side viewpoint: the target was found and
    no model built ("no front photo"). Ground is no obstacle: the model is built."""
    summary, texts = fly_data_scene("world-50007")
    assert any(
        "lie on the ground (parallax between the overview and the photos" in t for t in texts
    ), texts
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b05"
    assert summary.outcome.model_built


def test_the_ground_at_the_foot_of_a_building_of_its_hue_is_ground() -> None:
    """World scene 50246: a dark green ground (29, 83, 39) around green buildings, one of
    them at a car park's edge, its darker wall just outside the ground's outline. That wall
    was taken for the ground's own, so the ground, of the target's hue and as wide as the
    frame, stayed a building of unknown height, cut by the border from every look: "could
    not be judged", no match. The wall is joined, through shades of its paint, to its own
    roof: it is that building's, and the ground is ground by parallax."""
    summary, texts = fly_data_scene("world-50246")
    assert any("lie on the ground (parallax between the overviews)" in t for t in texts), texts
    assert not any("cut by the image border" in t for t in texts), texts
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b03"


def test_a_low_roof_is_not_ground_where_a_plane_below_the_least_telling_fits_it_better() -> None:
    """World scene 50119: the target, a small L 3.5 m tall (b03). One arm of its roof, drawn
    as its own region, fitted the ground better than every plane from 3 m up (the lowest the
    pair of photos told from the ground), and was taken for ground: the target was never
    judged and the flight ended "no building matched". A plane of 2 m, too low to tell from
    the ground by itself, fitted it better still; a region is ground only when no plane does."""
    summary, events = fly_data_scene("world-50119")
    assert any("target is point of interest" in e for e in events), events
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b03"


@pytest.mark.parametrize(
    ("scene", "target"),
    [
        pytest.param("world-50041", "b00", id="road-the-target-stands-on"),
        pytest.param("world-50309", "b01", id="road-behind-the-target"),
    ],
)
def test_a_road_beyond_the_overview_is_no_building_beside_a_side_viewpoint(
    scene: str, target: str
) -> None:
    """The right viewpoint lay beyond the overview's ground, over or beside a road. The
    look down from the ceiling took every region not of the ground's colour for a building
    that may stand there ("a building may stand 0.0 m from it", 50041; "2.3 m", 50309):
    no right photo, no model. Parallax against the photos the flight took from the ceiling
    shows the road lies on the ground. The ground a measured roof hides in those photos is
    left out, as no evidence: on 50041 the target stands on the road, and the patch beside
    it, hidden from the others, once stood out; on 50309 the road passes behind the target,
    and the photos it hides it in told it stands. The photo is taken and the model built."""
    summary, events = fly_data_scene(scene)
    cleared = "right viewpoint: beyond the overview's ground; no building near it below"
    assert cleared in events, events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == target


def test_a_road_joining_a_building_to_the_frame_leaves_it_a_region_of_its_own() -> None:
    """World scene 50063: a grey road crosses the overview from border to border, and the
    target's near twin (b03, a stepped cross of its colour) stands at its edge. In the
    overview they were one region, cut by the frame: a roof as high as the ceiling might
    stand anywhere the twin might, every look at it stayed at the ceiling, drawn too small
    to judge, and the flight ended "could not be judged". Told colour by colour against the
    survey's photos, the road lies on the ground (the towers leaning over it in those
    photos hide it there, and tell nothing): a cross is looked at again from below the
    ceiling (117 m). Both crosses then match, their outlines not compared (the target
    picture shows a higher part); photographed as the picture was, the twin's roof shows
    none, the target's does, and the target is found (before, the flight ended NO_MATCH,
    neither told from the other)."""
    summary, events = fly_data_scene("world-50063")
    again = [float(e.rsplit("at ", 1)[1].split(" m")[0]) for e in events if "looking again" in e]
    assert again and min(again) < 110.0, events
    assert not any("could not be judged" in e for e in events), events
    assert any("the only one whose roof shows a higher part" in e for e in events), events
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building


def _looks_from_ceiling(scene: Scene) -> tuple[Photo, list[Photo]]:
    """Photos of ``scene`` straight down from 117 m: a look down over home, and two others
    from the ceiling elsewhere (north-west and south-east of it)."""
    k = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)

    def photo(tag: str, x: float, y: float) -> Photo:
        pose = CameraPose((x, y, 117.0), 0.0, -90.0)
        return Photo(0, 0, tag, 0, pose, k, render(scene, pose, k))

    return photo("peek-1", 0.0, 0.0), [
        photo("overview-2", -20.0, 45.0),
        photo("measure-1", 35.0, -25.0),
    ]


def test_a_look_down_clears_a_road_but_not_a_tower_of_its_grey_beside_it() -> None:
    """A grey road, and a 20 m tower of the road's own grey touching it: in a look down from
    the ceiling they are one region of one colour. Parallax against photos from elsewhere
    shows the road on the ground only where no photo tells the part stands: the tower's
    walls and the road they join stay; a lane of its own, seen across from elsewhere, is
    cleared. (A uniform strip seen from along its length only cannot be told: it stays.)"""
    grey = [86, 87, 86]
    scene = scene_from_dict(
        {
            "target": "red",
            "ground": {
                "color": [56, 93, 50],
                "areas": [
                    {"name": "road", "color": grey,
                     "polygon": [[-60, -12], [60, -12], [60, -6], [-60, -6]]},
                    {"name": "lane", "color": grey,
                     "polygon": [[-60, 14], [60, 14], [60, 20], [-60, 20]]},
                ],
                "texture": {"kind": "noise", "amplitude_dn": 8.5, "scale_m": 1.1, "seed": 3},
            },
            "buildings": [
                {"name": "red", "color": [210, 40, 40],
                 "blocks": [{"footprint": [[30, 30], [40, 30], [40, 38], [30, 38]], "top_m": 8}]},
                {"name": "tower", "color": grey,
                 "blocks": [{"footprint": [[-4, -6], [4, -6], [4, 2], [-4, 2]], "top_m": 20}]},
            ],
        }
    )  # fmt: skip
    look, others = _looks_from_ceiling(scene)
    m = SearchMission(Params(), MissionInputs(look.image_rgb))
    before = Peek.of(look, m.params.vectorize)
    after = Peek.of(look, m.params.vectorize, standing_regions(m, look, others))
    assert before is not None and after is not None
    lane, tower = (-30.0, 17.0), (0.0, -2.0)
    assert before.clear_m(lane) == 0.0
    assert after.clear_m(lane) > 5.0  # the lane lies on the ground
    assert after.clear_m(tower) == 0.0  # the tower stands, and the road joining it
    assert after.clear_m((20.0, -9.0)) == 0.0
    # Measured, the tower hides the road behind it in the other photos (no evidence there),
    # and stands in the look whatever its road does.
    known = [(((-4.0, -6.0), (4.0, -6.0), (4.0, 2.0), (-4.0, 2.0)), 20.0)]
    measured = Peek.of(look, m.params.vectorize, standing_regions(m, look, others, known))
    assert measured is not None
    assert measured.clear_m(tower) == 0.0
    assert measured.clear_m(lane) > 5.0
    unseen = standing_regions(m, look, ())  # nothing to tell by: everything stands
    every = not_ground_regions(look.image_rgb, m.params.vectorize)
    assert [r.area_px for r in unseen] == [r.area_px for r in every]


def test_a_building_leaning_over_a_road_in_another_photo_does_not_keep_the_road_standing() -> None:
    """A grey lane, and a 30 m teal tower of unknown height at its edge. From elsewhere the
    tower leans over the lane: carried as the ground, the lane's pixels there are drawn in
    teal, and a patch that stands out kept the whole lane standing (world 50063: the road
    joined a building to the overview's border, and the building's region, cut by the
    frame, might hold a roof as high as the ceiling, so no look could go lower). Another
    roof's paint in another photo hides the ground there and tells nothing: the lane is
    cleared, the tower stands."""
    grey = [86, 87, 86]
    scene = scene_from_dict(
        {
            "target": "red",
            "ground": {
                "color": [56, 93, 50],
                "areas": [{"name": "lane", "color": grey,
                           "polygon": [[-60, 14], [60, 14], [60, 20], [-60, 20]]}],
                "texture": {"kind": "noise", "amplitude_dn": 8.5, "scale_m": 1.1, "seed": 3},
            },
            "buildings": [
                {"name": "red", "color": [210, 40, 40],
                 "blocks": [{"footprint": [[30, 30], [40, 30], [40, 38], [30, 38]], "top_m": 8}]},
                {"name": "teal", "color": [40, 190, 170],
                 "blocks": [{"footprint": [[-10, 20], [-2, 20], [-2, 28], [-10, 28]],
                             "top_m": 30}]},
            ],
        }
    )  # fmt: skip
    look, others = _looks_from_ceiling(scene)  # from the north-west, the tower leans over
    m = SearchMission(Params(), MissionInputs(look.image_rgb))
    peek = Peek.of(look, m.params.vectorize, standing_regions(m, look, others))
    assert peek is not None
    assert peek.clear_m((-40.0, 17.0)) > 5.0  # the lane lies on the ground
    assert peek.clear_m((-6.0, 16.0)) > 0.0  # beside the tower too
    assert peek.clear_m((-6.0, 24.0)) == 0.0  # the tower stands
