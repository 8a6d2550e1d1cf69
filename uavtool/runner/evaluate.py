"""How well a flight did against the scene's ground truth (only the runner knows the scene;
the mission never sees it): which building was matched, and the model's volumetric IoU."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from uavtool.world import Scene, building_footprint, building_mesh

if TYPE_CHECKING:
    from uavtool.runner.runner import Runner


@dataclass(frozen=True, slots=True)
class Evaluation:
    """``visited`` names the buildings at the points of interest photographed, in order."""

    visited: tuple[str, ...] = ()
    matched_building: str = ""
    target_building: str = ""
    model_iou: float | None = None


def evaluate(runner: Runner, scene: Scene | None) -> Evaluation:
    if scene is None:
        return Evaluation()
    mission = runner.mission
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
    iou = None
    if mission.model is not None:
        iou = model_iou(mission.model.vertices_m, mission.model.faces, scene, offset)
    return Evaluation(visited, matched, scene.target, iou)


def nearest_building(scene: Scene, point_en: tuple[float, float]) -> str:
    import shapely  # noqa: PLC0415

    p = shapely.Point(point_en)
    return min(scene.buildings, key=lambda b: building_footprint(b).distance(p)).name


def model_iou(
    vertices_m: Any, faces: Any, scene: Scene, offset_en: tuple[float, float] = (0.0, 0.0)
) -> float:
    """Volumetric IoU of a mesh (vehicle-home ENU) with the scene's target building."""
    import manifold3d  # noqa: PLC0415

    v = np.asarray(vertices_m, dtype=np.float64) + np.array([offset_en[0], offset_en[1], 0.0])
    model = manifold3d.Manifold(
        manifold3d.Mesh(v.astype(np.float32), np.asarray(faces, dtype=np.uint32))
    )
    truth_mesh = building_mesh(scene.target_building)
    truth = manifold3d.Manifold(
        manifold3d.Mesh(
            np.asarray(truth_mesh.vertices, dtype=np.float32),
            np.asarray(truth_mesh.faces, dtype=np.uint32),
        )
    )
    inter = (model ^ truth).volume()
    union = model.volume() + truth.volume() - inter
    return inter / union if union > 0 and math.isfinite(union) else 0.0
