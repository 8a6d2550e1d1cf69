"""How well a flight did against the scene's ground truth (only the runner knows the scene;
the mission never sees it): which building was matched, the model's volumetric IoU, whether
the model kept the target's tunnels, and how close the vehicle came to any building."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from uavtool.mission import SearchMission
from uavtool.world import Scene, building_footprint, building_solid

if TYPE_CHECKING:
    from uavtool.runner.runner import Runner


@dataclass(frozen=True, slots=True)
class Evaluation:
    """``visited`` names the buildings at the points of interest photographed, in order."""

    visited: tuple[str, ...] = ()
    matched_building: str = ""
    target_building: str = ""
    model_iou: float | None = None
    tunnel_kept: bool | None = None
    """Whether the model is open where the target has a tunnel (None: the target has none, or
    there is no model)."""
    clearance_m: float | None = None
    """Least distance between the vehicle's body and any building while airborne."""
    clearance_building: str = ""


def evaluate(runner: Runner, scene: Scene | None) -> Evaluation:
    if scene is None:
        return Evaluation()
    mission = runner.mission
    if not isinstance(mission, SearchMission):  # only the built-in mission has a target
        return Evaluation(target_building=scene.target)
    outcome = mission.outcome
    plan = mission.plan
    if outcome is None or plan is None:
        return Evaluation(target_building=scene.target)
    offset = runner.scene_offset

    def building_at(poi: int) -> str:
        x, y = plan.pois[poi].pos_en_m
        return nearest_building(scene, (x + offset[0], y + offset[1]))

    visited = tuple(building_at(k) for k in outcome.visited)
    matched = building_at(outcome.matched_poi) if outcome.matched_poi >= 0 else ""
    if mission.viewpoints is not None:  # the building it went on to photograph from above
        ring = [(x + offset[0], y + offset[1]) for x, y in mission.viewpoints.footprint_en_m]
        matched = building_under(scene, ring)
    iou = kept = None
    if mission.model is not None:
        iou = model_iou(mission.model.vertices_m, mission.model.faces, scene, offset)
        kept = tunnel_kept(mission.model.vertices_m, mission.model.faces, scene, offset)
    return Evaluation(visited, matched, scene.target, iou, kept)


def closest_clearance(
    route_enu_m: Sequence[tuple[float, float, float]],
    scene: Scene,
    *,
    body_radius_m: float,
    offset_en: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, str]:
    """(least gap between a sphere of ``body_radius_m`` along the route and any building,
    that building's name); ``(inf, "")`` for an empty route or scene. Route points are in
    the vehicle's ENU frame, ``offset_en`` its home in the scene's frame."""
    from uavtool.sitl.obstacles import ObstacleField  # noqa: PLC0415
    from uavtool.world.obstacles import scene_obstacles  # noqa: PLC0415

    field = ObstacleField(scene_obstacles(scene))
    best, name = math.inf, ""
    for x, y, z in route_enu_m:
        distance, prism = field.nearest(x + offset_en[0], y + offset_en[1], z)
        if prism is not None and distance - body_radius_m < best:
            best, name = distance - body_radius_m, prism.name
    return best, name


def tunnel_kept(
    vertices_m: Any, faces: Any, scene: Scene, offset_en: tuple[float, float] = (0.0, 0.0)
) -> bool | None:
    """Whether a model (vehicle-home ENU) is open where the target building has a tunnel: at
    half the height of each raised block, over the part of its footprint no lower block
    fills. None when the target has no raised block."""
    import manifold3d  # noqa: PLC0415
    import shapely  # noqa: PLC0415

    blocks = scene.target_building.blocks
    points = []
    for block in blocks:
        if block.base_m <= 0.0:
            continue
        under = shapely.Polygon(block.footprint_enu_m)
        for other in blocks:
            if other is not block and other.top_m <= block.base_m + 1e-6:
                under = under.difference(shapely.Polygon(other.footprint_enu_m))
        if under.area < 0.5:  # resting on what is below it all over: no tunnel
            continue
        inner = under.buffer(-0.3)  # away from the walls, where a model may bulge a little
        p = (inner if not inner.is_empty else under).representative_point()
        points.append((p.x - offset_en[0], p.y - offset_en[1], block.base_m / 2.0))
    if not points:
        return None
    model = _manifold(vertices_m, faces)
    probe_m = 0.2  # a small cube at each point: open if the model holds none of it
    for x, y, z in points:
        cube = manifold3d.Manifold.cube([probe_m] * 3, center=True).translate([x, y, z])
        if (model ^ cube).volume() > 0.0:
            return False
    return True


def _manifold(vertices_m: Any, faces: Any, offset_en: tuple[float, float] = (0.0, 0.0)) -> Any:
    import manifold3d  # noqa: PLC0415

    v = np.asarray(vertices_m, dtype=np.float64) + np.array([offset_en[0], offset_en[1], 0.0])
    return manifold3d.Manifold(
        manifold3d.Mesh(v.astype(np.float32), np.asarray(faces, dtype=np.uint32))
    )


def nearest_building(scene: Scene, point_en: tuple[float, float]) -> str:
    import shapely  # noqa: PLC0415

    p = shapely.Point(point_en)
    return min(scene.buildings, key=lambda b: building_footprint(b).distance(p)).name


def building_under(scene: Scene, ring_en: Sequence[tuple[float, float]]) -> str:
    """The building whose footprint overlaps the polygon ``ring_en`` (scene ENU m) most; the
    nearest one when none overlaps it. (A vertex average is no place to look: an L's or a
    U's lies in its inner corner, maybe inside a neighbour, a courtyard's in its yard.)"""
    import shapely  # noqa: PLC0415

    area = shapely.Polygon(ring_en).buffer(0)  # a self-touching outline still has an area
    overlaps = [(building_footprint(b).intersection(area).area, b.name) for b in scene.buildings]
    best_m2, name = max(overlaps, default=(0.0, ""))
    if best_m2 > 0.0:
        return name
    return nearest_building(scene, (area.centroid.x, area.centroid.y))


def model_iou(
    vertices_m: Any, faces: Any, scene: Scene, offset_en: tuple[float, float] = (0.0, 0.0)
) -> float:
    """Volumetric IoU of a mesh (vehicle-home ENU) with the scene's target building."""
    model = _manifold(vertices_m, faces, offset_en)
    truth = building_solid(scene.target_building)
    inter = (model ^ truth).volume()
    union = model.volume() + truth.volume() - inter
    return inter / union if union > 0 and math.isfinite(union) else 0.0
