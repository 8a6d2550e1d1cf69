"""The world: declarative scenes, ground-truth meshes and the deterministic camera renderer.

>>> from uavtool.world import load_scene, render
>>> from uavtool.camera import CameraPose, Intrinsics
>>> scene = load_scene("paper")
>>> image = render(scene, CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), Intrinsics.from_hfov())
>>> image.shape
(480, 640, 3)
"""

from uavtool.world.errors import SceneError
from uavtool.world.meshes import building_footprint, building_mesh, building_solid
from uavtool.world.render import render
from uavtool.world.scene import (
    Block,
    Building,
    Lighting,
    Scene,
    builtin_scene_names,
    load_scene,
    scene_from_dict,
    scene_to_dict,
)

__all__ = [
    "Block",
    "Building",
    "Lighting",
    "Scene",
    "SceneError",
    "building_footprint",
    "building_mesh",
    "building_solid",
    "builtin_scene_names",
    "load_scene",
    "render",
    "scene_from_dict",
    "scene_to_dict",
]
