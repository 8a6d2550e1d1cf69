from __future__ import annotations

import dataclasses
import functools
import math

import manifold3d
import numpy as np
import pytest
import trimesh

from uavtool.camera import CameraPose, Intrinsics
from uavtool.vision import vectorize
from uavtool.vision.errors import ModelInputError
from uavtool.vision.model3d import (
    Model,
    View,
    build_model,
    model_glb,
    open_beneath,
    same_colour,
)
from uavtool.vision.shapes import cut_edges
from uavtool.world import building_mesh, load_scene, render

K = Intrinsics.from_hfov()
# Around the paper scene's red target (x 5..15 m east, y -12..-4 m north, 5 / 6.5 m high).
POSES = {
    "top": CameraPose((10.0, -8.0, 20.0), 0.0, -90.0),
    "front": CameraPose((10.0, -27.0, 3.0), 0.0, 0.0),  # south of it, looking north
    "right": CameraPose((30.0, -8.0, 3.0), 270.0, 0.0),  # east of it, looking west
}


def _manifold(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    return manifold3d.Manifold(
        manifold3d.Mesh(
            vert_properties=np.asarray(mesh.vertices, np.float32),
            tri_verts=np.asarray(mesh.faces, np.uint32),
        )
    )


def _occupied(mesh: trimesh.Trimesh, point: tuple[float, float, float]) -> bool:
    probe = manifold3d.Manifold.cube((0.1, 0.1, 0.1), center=True).translate(point)
    return (_manifold(mesh) ^ probe).volume() > 1e-6


def _views(poses: dict[str, CameraPose]) -> dict[str, View]:
    scene = load_scene("paper")
    red = scene.building("red").color_rgb
    return {
        name: View(
            same_colour(vectorize(render(scene, pose, K, noise_seed=7)), red, hue_tolerance_deg=15),
            pose,
            K,
        )
        for name, pose in poses.items()
    }


@functools.cache
def _paper_model() -> Model:
    v = _views(POSES)
    return build_model(v["top"], v["front"], v["right"])


def test_paper_target_model_is_watertight_with_the_right_size() -> None:
    model = _paper_model()
    truth = building_mesh(load_scene("paper").building("red"))
    assert model.mesh.is_watertight
    assert model.mesh.volume == pytest.approx(truth.volume, rel=0.15)
    np.testing.assert_allclose(model.mesh.bounds[:, :2], truth.bounds[:, :2], atol=0.1)
    assert model.mesh.bounds[0, 2] == pytest.approx(0.0, abs=1e-6)
    assert model.height_m == pytest.approx(6.5, abs=0.8)
    a, b = _manifold(model.mesh), _manifold(truth)
    inter = (a ^ b).volume()
    assert inter / (a.volume() + b.volume() - inter) > 0.82


def test_through_holes_survive_as_tunnels() -> None:
    mesh = _paper_model().mesh
    assert not _occupied(mesh, (8.75, -10.0, 1.0))  # north-south tunnel, seen from the front
    assert not _occupied(mesh, (13.0, -6.25, 1.5))  # east-west tunnel, seen from the right
    assert _occupied(mesh, (8.75, -10.0, 4.0))  # the wing above the tunnel
    assert _occupied(mesh, (6.0, -10.0, 2.0))


def test_glb_round_trips_through_trimesh() -> None:
    data = model_glb(_paper_model())
    assert data[:4] == b"glTF"
    loaded = trimesh.load(trimesh.util.wrap_as_stream(data), file_type="glb", force="mesh")
    assert loaded.volume == pytest.approx(_paper_model().mesh.volume, rel=1e-4)


def test_bad_views_are_refused_with_a_reason() -> None:
    v = _views(POSES)
    with pytest.raises(ModelInputError, match="apart"):
        build_model(v["top"], v["front"], v["front"])
    with pytest.raises(ModelInputError, match="nadir"):
        build_model(v["front"], v["front"], v["right"])
    with pytest.raises(ModelInputError, match="no silhouette"):
        build_model(View((), POSES["top"], K), v["front"], v["right"])


def _arch_scene_views(building: str, poses: dict[str, CameraPose]) -> dict[str, View]:
    scene = load_scene("arch")
    colour = scene.building(building).color_rgb
    return {
        name: View(
            same_colour(
                vectorize(render(scene, pose, K, noise_seed=7)), colour, hue_tolerance_deg=15
            ),
            pose,
            K,
        )
        for name, pose in poses.items()
    }


def test_open_beneath_tells_a_building_on_its_footprint_from_one_with_tunnels() -> None:
    # Green in the `arch` scene: a stepped tower (8 × 8 m to 9 m, 4 × 4 m to 15 m).
    v = _arch_scene_views(
        "green",
        {
            "top": CameraPose((12.0, 10.0, 40.0), 0.0, -90.0),
            "front": CameraPose((12.0, 40.0, 8.0), 180.0, 0.0),  # north, looking south
            "right": CameraPose((40.0, 10.0, 8.0), 270.0, 0.0),  # east, looking west
        },
    )
    assert open_beneath(build_model(v["top"], v["front"], v["right"])) < 0.02
    # Paper's red has two tunnels through it, seen through from the front and the right.
    assert open_beneath(_paper_model()) > 0.15


def test_a_diagonal_view_carves_what_the_square_on_views_cannot_see_through() -> None:
    """The `arch` scene's red: an L-shaped deck 4–8 m up on two pillars under the ends of
    its legs. Its corner (x 4–8, y −16…−12) stands on nothing, but from the south and from
    the east a pillar stands behind it: only a diagonal view sees through under it."""
    v = _arch_scene_views(
        "red",
        {
            "top": CameraPose((10.0, -11.5, 30.0), 0.0, -90.0),
            "front": CameraPose((10.0, -38.0, 6.0), 0.0, 0.0),  # south, looking north
            "right": CameraPose((38.0, -11.5, 6.0), 270.0, 0.0),  # east, looking west
            "diagonal": CameraPose((28.0, -32.0, 6.0), 315.0, 0.0),  # south-east, looking NW
        },
    )
    corner, deck = (6.0, -14.0, 2.0), (6.0, -14.0, 6.0)
    three = build_model(v["top"], v["front"], v["right"])
    assert open_beneath(three) > 0.15  # under the legs, seen through from the side
    assert _occupied(three.mesh, corner)
    four = build_model(v["top"], v["front"], v["right"], more=(v["diagonal"],))
    assert not _occupied(four.mesh, corner)
    assert _occupied(four.mesh, deck)
    assert four.mesh.is_watertight
    assert four.mesh.volume < three.mesh.volume


def test_a_foot_below_the_frame_is_said_nothing_about() -> None:
    """A front photo so close and low that the building's foot is below the frame: the
    silhouette touches the bottom edge. As it is, the outline is incomplete and refused;
    marked as a view whose foot the photo does not show, the model is built, standing on
    the ground, as large as from a whole front photo. A cut at another edge still fails."""
    close = dict(POSES, front=CameraPose((10.0, -22.0, 5.0), 0.0, 0.0))  # 10 m south, low
    v = _views(close)
    assert cut_edges(v["front"].shapes, K) == {"bottom"}
    with pytest.raises(ModelInputError, match="touches the image border"):
        build_model(v["top"], v["front"], v["right"])
    front = dataclasses.replace(v["front"], foot_hidden=True)
    model = build_model(v["top"], front, v["right"])
    assert model.mesh.is_watertight
    assert model.mesh.bounds[0, 2] == pytest.approx(0.0, abs=1e-6)
    assert model.mesh.volume == pytest.approx(_paper_model().mesh.volume, rel=0.1)
    beside = _views(dict(POSES, front=CameraPose((4.0, -22.0, 5.0), 0.0, 0.0)))["front"]
    assert "left" in cut_edges(beside.shapes, K) or "right" in cut_edges(beside.shapes, K)
    with pytest.raises(ModelInputError, match="touches the image border"):
        build_model(v["top"], dataclasses.replace(beside, foot_hidden=True), v["right"])


def _around(direction_deg: float, distance_m: float, alt_m: float) -> CameraPose:
    """A level camera ``distance_m`` from the red target's centre, in ``direction_deg``
    (compass) from it, looking at it."""
    a = math.radians(direction_deg)
    x, y = 10.0 + distance_m * math.sin(a), -8.0 + distance_m * math.cos(a)
    return CameraPose((x, y, alt_m), math.degrees(math.atan2(10.0 - x, -8.0 - y)) % 360.0, 0.0)


def test_side_views_whose_foot_is_hidden_are_cut_to_what_the_top_view_sees() -> None:
    """Front and right photos turned 25° from square-on (40° apart), both marked as not
    showing the building's foot: each one's cone holds everything below its silhouette,
    and the two also meet far behind the building, high above it (44.7 m here; 223.6 m in
    town scene 3242), which was refused as reaching the top camera. The building is only
    what the top view sees of them: its model stands on the ground, about as tall as the
    red target (6.5 m; less carved without the foot, 7.4 m)."""
    v = _views(dict(POSES, front=_around(155.0, 19.0, 3.0), right=_around(115.0, 20.0, 3.0)))
    front = dataclasses.replace(v["front"], foot_hidden=True)
    right = dataclasses.replace(v["right"], foot_hidden=True)
    model = build_model(v["top"], front, right)
    assert model.height_m == pytest.approx(_paper_model().height_m, abs=1.0)
    assert model.mesh.bounds[0, 2] == pytest.approx(0.0, abs=1e-6)


def test_a_side_photo_that_sees_only_part_of_the_building_builds_no_model() -> None:
    """A front photo whose right half is hidden (as behind a neighbour, taken for the
    ground): carved by it, the model leaves out what the top photo shows of the building's
    eastern part. A model of part of the building is refused, saying how much it leaves
    out; the whole photo builds it."""
    scene = load_scene("paper")
    red = scene.building("red").color_rgb
    image = render(scene, POSES["front"], K, noise_seed=7)
    half = image.copy()
    half[:, 330:] = scene.ground_rgb  # east of the building's middle, seen from the south
    hidden = View(same_colour(vectorize(half), red, hue_tolerance_deg=15), POSES["front"], K)
    v = _views(POSES)
    with pytest.raises(ModelInputError, match=r"the side photos leave out \d+% of what the top"):
        build_model(v["top"], hidden, v["right"])
    assert build_model(v["top"], v["front"], v["right"]).mesh.is_watertight
