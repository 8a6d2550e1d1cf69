"""Where a simulated scene sits on the Earth when the vehicle is not the built-in one.

A scene is ENU metres around its origin, so placing it is a choice of origin: at the
vehicle's home (the default: ArduPilot users start SITL wherever they like), or at the
scene's own geographic origin, which only makes sense when the vehicle is there.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.runner.preflight import PreflightError
from uavtool.world import Scene

SCENE_ORIGINS = ("vehicle", "scene")
MARGIN_M = 50.0
"""How far beyond its outermost building a scene still counts as in view."""


def scene_extent_m(scene: Scene) -> float:
    """The distance from the scene's origin to its farthest building corner, plus a margin."""
    corners = [c for b in scene.buildings for blk in b.blocks for c in blk.footprint_enu_m]
    return max((math.hypot(x, y) for x, y in corners), default=0.0) + MARGIN_M


def place_scene(
    scene: Scene, vehicle_home: GeoPoint, origin: str, say: Callable[[str], None]
) -> GeoPoint:
    """The geographic origin to render ``scene`` around. ``"scene"`` keeps the scene's and
    raises PreflightError, with the ``--home`` to start ArduPilot's SITL with, when the
    vehicle's home is beyond the scene's extent."""
    if origin == "vehicle":
        say(f"scene {scene.name!r} placed at the vehicle's home (--scene-origin vehicle)")
        return vehicle_home
    east, north, _ = enu_from_geo(scene.home, vehicle_home)
    away_m = math.hypot(east, north)
    h = scene.home
    start_at = f"--home {h.lat_deg:.7f},{h.lon_deg:.7f},{h.alt_amsl_m:g},{scene.home_heading_deg:g}"
    if away_m > scene_extent_m(scene):
        raise PreflightError(
            f"the vehicle is {away_m / 1000.0:.1f} km from scene {scene.name!r}, beyond its "
            f"{scene_extent_m(scene):.0f} m: start ArduPilot's SITL with {start_at}, "
            "or use --scene-origin vehicle"
        )
    if away_m > 1.0:
        say(f"the vehicle's home is {away_m:.0f} m from the scene's origin ({start_at}: none)")
    return scene.home
