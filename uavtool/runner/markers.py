"""The flight as 3D markers (``/mission/scene``): the route flown, each photo's pose, the
points of interest and the viewpoints, which Foxglove's and Lichtblick's 3D panels draw
without setup. Every update carries every entity known so far (route, photos, and the points
of interest and viewpoints once planned): a viewer that seeks shows only the last message of
a topic before the playhead, and that one then holds the whole picture."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from uavtool.camera import CameraPose
from uavtool.recording import Pose, SceneEntity, SceneMarkers
from uavtool.recording.values import Vec3

_ROUTE_STEP_M = 0.5  # a route point every half metre is smooth at any zoom and stays small
_ROUTE = (1.0, 0.55, 0.0, 1.0)
_PHOTO = (0.1, 0.8, 1.0, 1.0)
_POI = (1.0, 0.2, 0.6, 0.8)
_VIEWPOINT = (0.3, 1.0, 0.3, 1.0)


def view_pose(pos_enu_m: Vec3, heading_deg: float, pitch_deg: float) -> Pose:
    """A pose whose x axis looks along ``heading_deg`` (clockwise from north) and
    ``pitch_deg`` (−90 straight down), in ENU."""
    yaw, tilt = math.radians(90.0 - heading_deg) / 2.0, math.radians(-pitch_deg) / 2.0
    cz, sz, cy, sy = math.cos(yaw), math.sin(yaw), math.cos(tilt), math.sin(tilt)
    # q = q_z(yaw) ⊗ q_y(tilt): turn to the heading, then tip the nose down
    return Pose(pos_enu_m, (-sz * sy, cz * sy, sz * cy, cz * cy))


class RouteMarkers:
    """Collects what the markers show; each method returns the update to record, if any."""

    def __init__(self) -> None:
        self._route: list[Vec3] = []
        self._photos: list[Pose] = []
        self._planned: dict[str, SceneEntity] = {}  # "pois", "viewpoints": the latest

    def telemetry(self, pos_enu_m: Vec3) -> None:
        if not self._route or math.dist(self._route[-1], pos_enu_m) >= _ROUTE_STEP_M:
            self._route.append(pos_enu_m)

    def photo(self, pose: CameraPose) -> SceneMarkers:
        self._photos.append(view_pose(pose.pos_enu_m, pose.heading_deg, pose.pitch_deg))
        return self._flight()

    def output(self, data: Mapping[str, Any]) -> SceneMarkers | None:
        """Markers for a Plan (points of interest), Viewpoints, or the Outcome (whole route)."""
        kind = data.get("type")
        if kind == "Plan":
            pois = data.get("pois", [])
            at = [(*p["pos_en_m"], p["roof_m"]) for p in pois]
            labels = tuple((a, f"POI {p['index']}") for a, p in zip(at, pois, strict=True))
            self._planned["pois"] = SceneEntity(
                "pois", _POI, spheres_m=tuple(at), texts=labels, size_m=3.0
            )
            return self._flight()
        if kind == "Viewpoints":
            views = [data[k] for k in ("top", "front", "right") if "pos_enu_m" in data.get(k, {})]
            arrows = tuple(
                view_pose(tuple(v["pos_enu_m"]), v["heading_deg"], v["pitch_deg"]) for v in views
            )
            texts = tuple((tuple(v["pos_enu_m"]), str(v["name"])) for v in views)
            self._planned["viewpoints"] = SceneEntity(
                "viewpoints", _VIEWPOINT, arrows=arrows, texts=texts, size_m=4.0
            )
            return self._flight()
        if kind == "Outcome":
            return self._flight()
        return None

    def _flight(self) -> SceneMarkers:
        return SceneMarkers(
            (
                SceneEntity("route", _ROUTE, line_m=tuple(self._route)),
                SceneEntity("photos", _PHOTO, arrows=tuple(self._photos), size_m=3.0),
                *self._planned.values(),
            )
        )
