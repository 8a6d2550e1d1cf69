"""Roofs the survey left of unknown height, measured by the looks that come after it.

A building of unknown height may stand anywhere along the rays through its outline, up to
just below the camera: near it, no look descends. The survey's tour measures what it can;
a look taken later, lower and elsewhere, sees from another place than any of the tour's,
and measures more. Each scene below is a world scene (``uavtool scene random --hard --town
--world --anywhere --seed N``) flown on the built-in vehicle, whose flight ended "which is
the target is not known" before: a building of the target's colour drawn too small to
judge, no closer look allowed over it."""

from __future__ import annotations

from tests.mission.scenes import fly_data_scene
from uavtool.mission import Status


def test_a_field_the_survey_could_not_place_is_found_on_the_ground_by_a_look() -> None:
    """World scene 50044: a field with buildings standing on it, which no photo of the
    survey told from a building, may be a tower up to 92 m over the whole way down to a
    candidate of the target's colour (an 18 m roof drawn too small from 96.6 m): the closer
    look was refused. The look itself told by parallax that the field lies on the ground,
    and the closer look followed. Since the field's walls are no longer taken from the
    buildings of its hue standing on its edge (`uavtool.mission.ground.wall_pixels`), the
    tour's photos tell it lies on the ground before any look (the look's own measuring
    is kept by world 50130, below). Either way the field holds nothing up, and the target
    is found."""
    summary, texts = fly_data_scene("world-50044")
    assert any("measured at last: it lies on the ground" in t for t in texts) or any(
        "more region(s) lie on the ground (parallax between the overview and the photos" in t
        for t in texts
    ), texts
    assert not any("drawn too small to judge" in t for t in texts), texts
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b00"


def test_a_rival_whose_roof_the_border_cut_is_measured_from_aside() -> None:
    """World scene 50011: the target (b03, a 43.9 m U) matches; a near shape of its colour
    and height, its roof cut by the overview's border, is drawn too small to judge from the
    ceiling. The survey measured it by the edges the border left: a height for plans, not
    one to descend by (a tier of a stepped tower once came out 21 m low that way), so it
    counted as high as its region allowed, and it held its own closer look up. Whole in the
    look and in a look from aside, its roof is measured, the look from closer tells it from
    the target."""
    summary, texts = fly_data_scene("world-50011")
    assert any("m aside, at 11" in t for t in texts), texts
    assert any("its roof measured 43.9 m above home: looking again from closer" in t for t in texts)
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b03"


def test_what_a_roof_measured_late_leaves_of_its_region_is_measured_too() -> None:
    """World scene 50130: the target's mirror image (b06, 7.6 m, the target's colour)
    touches a road in the overview, one region with it. Of unknown height, it explained
    its whole region; once a look from straight above measured its roof, the road was
    covered by nothing at all. What a roof measured late leaves of its region then stood
    of unknown height, as the survey's obstacles do (the road: up to 54 m, over the way
    down to the mirror image), until the look and the survey's photos told it lies on the
    ground. Since the survey tells what is left of a region off the ground colour by
    colour (`uavtool.mission.ground.regions_off_ground`), the road is no part of the
    mirror image's region before any look, and nothing is left to measure late. Either
    way the road holds nothing up: the mirror image is looked at from straight above,
    ruled out, and the target found."""
    summary, texts = fly_data_scene("world-50130")
    assert not any("measured at last" in t and "roof" in t for t in texts), texts
    assert any("looking again from straight above it" in t for t in texts), texts
    assert any("as much like the target's mirror image" in t for t in texts), texts
    assert summary.outcome.status is Status.COMPLETED, summary.outcome.reason
    assert summary.evaluation.matched_building == summary.evaluation.target_building == "b01"
