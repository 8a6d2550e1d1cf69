"""The paper's scenario, step by step: overview, points of interest, recognition, the three
photos for the model, and the model. Each step is a generator run by :class:`Mission`."""

from __future__ import annotations

from typing import TYPE_CHECKING

from uavtool.mission.measure import measure_from_above
from uavtool.mission.outputs import Level, Plan, Status
from uavtool.mission.search import search, target_hue_first
from uavtool.mission.survey import Survey, overview_heading_deg, survey
from uavtool.nav import route_length_m, visit_order

if TYPE_CHECKING:
    from uavtool.mission.base import Wait
    from uavtool.mission.mission import SearchMission


NO_GIMBAL_REASON = "target found, no model: the vehicle has no gimbal"


def fly(m: SearchMission) -> Wait[None]:
    """The whole flight up to (not including) the return home."""
    p = m.params.mission
    yield from m.wait_until(lambda _t: True, 0.0)  # the first telemetry
    last = m.last
    assert last is not None  # wait_until returned on telemetry
    if last.armed and not last.landed:
        m.event(Level.INFO, "already flying: taking control in GUIDED")
        yield from m.set_mode("GUIDED")
        m.airborne(flying=True)
    else:
        yield from m.take_off_to(p.overview_alt_m)
    here = m.last.pos_enu_m if m.last else (0.0, 0.0, 0.0)
    heading = overview_heading_deg(m.last.heading_deg if m.last else 0.0)
    yield from m.move((here[0], here[1], p.overview_alt_m), heading, "overview position")

    seen = yield from survey(m)
    if not seen.pois:
        raise m.end(Status.NO_MATCH, "the overview photos show no building")
    start = (m.last.pos_enu_m[0], m.last.pos_enu_m[1]) if m.last else (0.0, 0.0)
    seen = yield from measure_from_above(m, seen, visit_order(start, _points(seen)))
    pois = seen.pois
    points = _points(seen)
    order = target_hue_first(m, start, pois)
    m.plan = Plan(seen.photo.frame_index, pois, order, route_length_m(start, points, order))
    m.emit(m.plan)
    m.event(Level.INFO, f"{len(pois)} points of interest; visiting order {list(order)}")

    # Over every known roof by the safety margin, even where the vehicle flies the arrival
    # radius lower than told.
    transit_m = seen.highest_roof_m + m.params.viewpoints.safety_margin_m + p.arrive_radius_m
    m.transit_m = transit_m
    found = yield from search(
        m,
        pois,
        order,
        overview=seen.photo,
        overview_shapes=seen.shapes,
        transit_m=transit_m,
        roofless=seen.roofless,
        inspector=m.inspector(seen, transit_m),
    )
    m.searched(found)
    if found is None:
        return
    m.matched_poi = found.poi.index
    m.match_score = found.score
    if not p.gimbal:
        raise m.end(Status.PARTIAL, NO_GIMBAL_REASON)
    yield from m.model_target(found, seen, transit_m)


def _points(seen: Survey) -> list[tuple[float, float]]:
    return [poi.pos_en_m for poi in seen.pois]
