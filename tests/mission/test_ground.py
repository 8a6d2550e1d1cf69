"""Ground that is not one grey: a ground of a colour, lawns, roads and car parks, a painted
copy of the target on the ground. None is a building, a point of interest or an obstacle:
parallax between photos from above tells them (`uavtool.nav.parallax`)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import shapely

from tests.mission.driver import fly
from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission import Params, Photo, Status
from uavtool.mission.analysis import nadir_shapes
from uavtool.mission.ground import lies_on_ground
from uavtool.runner.fly import FlyConfig
from uavtool.runner.fly import fly as fly_scene
from uavtool.world import load_scene, render
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
