"""Ground-truth meshes and footprints."""

from __future__ import annotations

import pytest
import trimesh

from tests.world.bodies import body_count
from uavtool.world import building_footprint, building_mesh, load_scene


@pytest.mark.parametrize("scene_name", ["paper", "dense", "blocked-front"])
def test_every_building_is_a_watertight_solid_of_the_right_volume(scene_name: str) -> None:
    scene = load_scene(scene_name)
    for b in scene.buildings:
        mesh = building_mesh(b)
        assert mesh.is_watertight
        assert mesh.is_winding_consistent
        expected = sum(
            building_footprint_area(blk.footprint_enu_m) * (blk.top_m - blk.base_m)
            for blk in b.blocks
        )
        assert mesh.volume == pytest.approx(expected, rel=1e-6)
        lo, hi = mesh.bounds
        assert lo[2] == pytest.approx(min(blk.base_m for blk in b.blocks))
        assert hi[2] == pytest.approx(max(blk.top_m for blk in b.blocks))


def test_red_target_keeps_both_through_holes() -> None:
    red = load_scene("paper").target_building
    mesh = building_mesh(red)
    assert body_count(mesh) == 1  # touching blocks are merged
    tunnels = [(8.75, -10.0, 1.0), (13.0, -6.25, 1.5)]  # under the wing's and the leg's bridges
    walls = [(6.0, -10.0, 1.0), (8.75, -10.0, 4.0), (13.0, -8.0, 1.5), (13.0, -6.25, 5.0)]
    for point, solid in [(p, False) for p in tunnels] + [(p, True) for p in walls]:
        probe = trimesh.creation.box(extents=(0.2, 0.2, 0.2))
        probe.apply_translation(point)
        common = trimesh.boolean.intersection([mesh, probe], engine="manifold")
        inside = common.volume if len(common.faces) else 0.0
        assert inside == pytest.approx(0.008 if solid else 0.0, abs=1e-6), (
            point
        )  # manifold: float32
    fp = building_footprint(red)
    assert fp.geom_type == "Polygon"
    assert fp.area == pytest.approx(10 * 3.5 + 3.5 * 4.5)


def building_footprint_area(ring: tuple[tuple[float, float], ...]) -> float:
    from uavtool.world.polygon import signed_area

    return signed_area(ring)


def test_body_count_tells_apart_boxes_that_do_not_touch() -> None:
    a, b = trimesh.creation.box(extents=(1, 1, 1)), trimesh.creation.box(extents=(1, 1, 1))
    b.apply_translation((3.0, 0.0, 0.0))
    assert body_count(a) == 1
    assert body_count(trimesh.util.concatenate([a, b])) == 2
