"""A scene's buildings as the built-in vehicle's obstacles (the SITL knows nothing of scenes).

Imports :mod:`uavtool.sitl.obstacles`, so it is not re-exported by :mod:`uavtool.world`: only
code that starts the simulator needs it.
"""

from __future__ import annotations

from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.sitl.obstacles import Prism
from uavtool.world.scene import Scene


def scene_obstacles(scene: Scene, *, home: GeoPoint | None = None) -> tuple[Prism, ...]:
    """Every block of every building of ``scene`` as a :class:`Prism` named after its building,
    in the frame of a vehicle whose home is ``home`` (default: the scene's home, where the
    frames coincide). Another home moves the buildings sideways so that they stay where they
    are on the map; heights stay above the vehicle's home, whose ground is the scene's ground
    (as the simulated camera assumes)."""
    east_m = north_m = 0.0
    if home is not None:
        east_m, north_m, _ = enu_from_geo(home, scene.home)  # the scene's origin, seen from home
    return tuple(
        Prism(
            name=building.name,
            footprint_en_m=tuple((e + east_m, n + north_m) for e, n in block.footprint_enu_m),
            base_m=block.base_m,
            top_m=block.top_m,
        )
        for building in scene.buildings
        for block in building.blocks
    )
