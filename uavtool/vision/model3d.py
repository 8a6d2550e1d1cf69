"""3D model from three projections (paper III-C): top, front and right silhouettes.

Each photo's silhouette is turned into a solid using the camera pose and intrinsics at
capture, and the three solids are intersected (with the ground as a fourth cut):

* front and right: the silhouette's viewing cone — every ray from the camera centre through
  the silhouette. This is the exact perspective "extrusion along the view direction": a
  roof edge further away appears lower and narrower, and the cone puts it back at its true
  size wherever the other views place it. Holes in a silhouette (a tunnel seen end-on)
  are holes in the cone, so they become tunnels in the model.
* top: buildings have vertical walls, so the roof outline is the footprint. The top
  silhouette's rays are cut by the roof plane (its height measured in the side views; the
  two depend on each other and are iterated to a fixed point) and the outline is extruded
  straight down to the ground — a courtyard (hole seen from above) stays a hole.

Metric scale comes from the poses: no dimension is assumed. Booleans run in manifold3d,
whose output is always a closed 2-manifold, so the mesh is watertight by construction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics
from uavtool.geo import wrap_180
from uavtool.glb import mesh_glb
from uavtool.vision.colour import hue_distance_deg
from uavtool.vision.errors import ModelInputError
from uavtool.vision.params import ModelParams
from uavtool.vision.shapes import FloatArray, Shape, cut_edges

# Depth range of the side viewing cones, metres along the optical axis.
_NEAR_M = 0.25
_FAR_M = 2000.0
_COVERED = 0.5
"""The least share of the top view's footprint a model must cover seen from above. Carved
from whole silhouettes, a model shows in every photo as its silhouette there (measured:
0.999-1.0). Side photos that saw only part of the building (its top over its neighbours)
carve away more: a stepped tower seen so covered 0.67 (IoU 0.82), but a model leaving out
most of what the top photo shows is a model of something else (town scenes: 0.05 and 0.45,
IoU 0.05 and 0.41)."""
_BEYOND_M = 1.0
"""How far above what the top view sees the side views' solid may reach and still be the
same top (their outlines differ by a pixel or two; in metres at the roof, centimetres)."""


@dataclass(frozen=True, slots=True)
class View:
    """One photo's silhouette: the shapes of the object in it, with the camera at capture."""

    shapes: tuple[Shape, ...]
    pose: CameraPose
    intrinsics: Intrinsics
    foot_hidden: bool = False
    """The object's lower part is hidden behind something nearer (a camera looking down over
    a lower building) or below the frame: below its silhouette the photo says nothing, so
    nothing there is carved away (the top view's footprint still bounds it), and the
    silhouette may touch the frame's bottom edge."""


@dataclass(frozen=True, slots=True)
class Model:
    """The built model: a watertight triangle mesh in world ENU metres, and what was measured.

    ``vertices_m`` ``(n, 3)`` and ``faces`` ``(m, 3)``: the mesh as manifold3d made it (each
    edge shared by exactly two faces, faces counter-clockwise seen from outside);
    ``footprint_enu_m`` : the outer footprint ring ``(n, 2)``; ``height_m`` : the highest
    roof above the ground; ``volume_m3`` : the mesh's volume.
    """

    vertices_m: FloatArray
    faces: npt.NDArray[np.int64]
    height_m: float
    footprint_enu_m: FloatArray
    volume_m3: float

    @property
    def mesh(self) -> Any:
        """The mesh as a ``trimesh.Trimesh`` (imports trimesh, ~0.1 s the first time)."""
        import trimesh  # noqa: PLC0415 — heavy; the mission needs none of it

        return trimesh.Trimesh(vertices=self.vertices_m, faces=self.faces, process=True)


def build_model(
    top: View,
    front: View,
    right: View,
    params: ModelParams | None = None,
    *,
    more: Sequence[View] = (),
) -> Model:
    """The object's 3D model from its top, front and right views.

    ``more``: further side views (e.g. from a diagonal); each one's cone cuts the solid
    too, carving what the front and right views cannot see through (an arch's corner).

    Raises :class:`ModelInputError` when a view has no silhouette, a silhouette touches the
    image border (unless allowed), the top photo is not close to nadir, the side photos are
    not close to horizontal, or the two side headings are too close to each other.
    """
    import manifold3d  # noqa: PLC0415 — heavy; only model building needs it

    p = params if params is not None else ModelParams()
    _check_views(top, front, right, p, more)
    side = manifold3d.Manifold.batch_boolean(
        [_cone(view) for view in (front, right, *more)], manifold3d.OpType.Intersect
    )
    side = side.trim_by_plane((0.0, 0.0, 1.0), p.ground_z_m)
    if side.is_empty():
        raise ModelInputError(
            "the front and right silhouettes do not overlap in space: check the poses and "
            "that both photos show the same building"
        )
    # Only what the top photo sees of the side views' solid is the building: two views
    # whose foot is hidden (filled down past the frame) meet far off too, high up.
    seen = side ^ _cone(top)
    if seen.is_empty():
        raise ModelInputError(
            "the top silhouette does not overlap the front and right ones: check the poses "
            "and that each photo shows the same building"
        )
    h_start = float(side.bounding_box()[5])
    h_seen = float(seen.bounding_box()[5])
    if h_start > h_seen + _BEYOND_M:
        h_start = h_seen
    rings = _footprint(top, side, p.ground_z_m, p, h_start)
    solid = side ^ _prism(rings, p.ground_z_m, _FAR_M)
    if solid.is_empty():
        raise ModelInputError(
            "the top silhouette does not overlap the front and right ones: check the poses "
            "and that each photo shows the same building"
        )
    covered = _covered(solid, rings)
    if covered < _COVERED:
        raise ModelInputError(
            f"the side photos leave out {1.0 - covered:.0%} of what the top photo shows of the "
            "building: they saw only part of it (hidden behind its neighbours, or only its top)"
        )
    mesh = solid.to_mesh()
    vertices = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    faces = np.asarray(mesh.tri_verts, dtype=np.int64)
    height_m = float(vertices[:, 2].max()) - p.ground_z_m
    return Model(vertices, faces, height_m, rings[0], _volume(vertices, faces))


def _volume(vertices: FloatArray, faces: npt.NDArray[np.int64]) -> float:
    """A closed mesh's volume (the divergence theorem: each face's signed tetrahedron with
    the origin)."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _covered(solid: Any, rings: list[FloatArray]) -> float:
    """The share of the top view's footprint that the model covers seen from above."""
    import manifold3d  # noqa: PLC0415

    footprint = manifold3d.CrossSection([r.tolist() for r in rings], manifold3d.FillRule.EvenOdd)
    area = float(footprint.area())
    if area <= 0.0:
        return 0.0
    return float((solid.project() ^ footprint).area()) / area


def open_beneath(model: Model, *, ground_z_m: float = 0.0, above_m: float = 0.5) -> float:
    """The fraction of the model's largest horizontal section that is empty ``above_m`` over
    the ground: 0 for a building that stands on its whole footprint, large where the side
    photos saw through under it (an arch, a bridge, a deck on pillars)."""
    import manifold3d  # noqa: PLC0415

    solid = manifold3d.Manifold(
        manifold3d.Mesh(
            np.asarray(model.vertices_m, dtype=np.float32),
            np.asarray(model.faces, dtype=np.uint32),
        )
    )
    top = float(model.vertices_m[:, 2].max())
    low = ground_z_m + above_m
    if top <= low:
        return 0.0
    largest = max(float(solid.slice(float(z)).area()) for z in np.linspace(low, top - 1e-3, 16))
    if largest <= 0.0:
        return 0.0
    return max(0.0, 1.0 - float(solid.slice(low).area()) / float(largest))


def model_glb(model: Model) -> bytes:
    """The model's mesh as binary glTF bytes (:func:`uavtool.glb.mesh_glb`)."""
    return mesh_glb(model.vertices_m, model.faces)


def _check_views(top: View, front: View, right: View, p: ModelParams, more: Sequence[View]) -> None:
    sides = [
        ("front", front),
        ("right", right),
        *((f"side {i + 3}", v) for i, v in enumerate(more)),
    ]
    for name, view in [("top", top), *sides]:
        if not view.shapes:
            raise ModelInputError(f"{name}: no silhouette of the object in the photo")
        cut = cut_edges(view.shapes, view.intrinsics)
        if view.foot_hidden:
            cut -= {"bottom"}  # below the silhouette the photo says nothing anyway
        if not p.allow_border_cut and cut:
            raise ModelInputError(
                f"{name}: the object touches the image border, so its outline is incomplete; "
                "take the photo from further away"
            )
    if abs(top.pose.pitch_deg + 90.0) > p.max_top_tilt_deg:
        raise ModelInputError(
            f"top: gimbal pitch {top.pose.pitch_deg:g}° is not within "
            f"{p.max_top_tilt_deg:g}° of nadir (−90°)"
        )
    for name, view in sides:
        if abs(view.pose.pitch_deg) > p.max_side_tilt_deg:
            raise ModelInputError(
                f"{name}: gimbal pitch {view.pose.pitch_deg:g}° is not within "
                f"{p.max_side_tilt_deg:g}° of horizontal"
            )
    separation = abs(wrap_180(front.pose.heading_deg - right.pose.heading_deg))
    if min(separation, 180.0 - separation) < p.min_view_separation_deg:
        raise ModelInputError(
            f"front and right headings differ by {separation:g}°; they must be at least "
            f"{p.min_view_separation_deg:g}° apart (ideally 90°)"
        )


def _normalised_rings(view: View) -> list[FloatArray]:
    """Every ring of the view's shapes in normalised image coordinates ``(x/z, y/z)``."""
    k = view.intrinsics
    rings: list[FloatArray] = []
    for shape in view.shapes:
        for ring in (shape.polygon_px, *shape.holes_px):
            xn = (ring[:, 0] - k.cx_px) / k.fx_px
            yn = (ring[:, 1] - k.cy_px) / k.fy_px
            rings.append(np.stack([xn, yn], axis=1))
    return rings


def _cone(view: View) -> Any:
    """The viewing cone of a silhouette, between the near and far depths, in world ENU; for
    a view whose foot is hidden, of the silhouette and all below it in the image."""
    import manifold3d  # noqa: PLC0415

    rings = [r * _NEAR_M for r in _normalised_rings(_down_to_the_edge(view))]
    section = manifold3d.CrossSection(rings, manifold3d.FillRule.EvenOdd)
    scale = _FAR_M / _NEAR_M
    cone = section.extrude(_FAR_M - _NEAR_M, scale_top=(scale, scale)).translate((0, 0, _NEAR_M))
    return cone.transform(_world_from_camera_3x4(view.pose))


def _down_to_the_edge(view: View) -> View:
    """``view`` itself, or (foot hidden) one whose silhouette also holds every pixel below
    it in its column, down past the image's bottom edge: one outline, no holes."""
    if not view.foot_hidden:
        return view
    k = view.intrinsics
    mask = np.zeros((k.height_px, k.width_px), np.uint8)
    for shape in view.shapes:
        cv2.fillPoly(mask, [np.round(shape.polygon_px).astype(np.int32).reshape(-1, 1, 2)], 255)
    column_has = mask.any(axis=0)
    first = np.where(column_has, mask.argmax(axis=0), k.height_px)
    below = np.arange(k.height_px)[:, None] >= first[None, :]
    filled = np.where(below, 255, 0).astype(np.uint8)
    contours, _ = cv2.findContours(filled, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    shapes = []
    for contour in contours:
        outline: FloatArray = contour[:, 0, :].astype(np.float64)
        # past the bottom edge: the cone must reach below the lowest pixel's ray
        outline[outline[:, 1] >= k.height_px - 1, 1] = 2.0 * k.height_px
        shapes.append(Shape.from_rings(colour_rgb=(0, 0, 0), polygon_px=outline))
    return View(tuple(shapes), view.pose, view.intrinsics)


def _world_from_camera_3x4(pose: CameraPose) -> list[list[float]]:
    r = pose.world_from_camera()
    t = pose.pos_enu_m
    return [[float(r[i, 0]), float(r[i, 1]), float(r[i, 2]), float(t[i])] for i in range(3)]


def _footprint(
    top: View, side: Any, ground_z_m: float, p: ModelParams, h_start: float
) -> list[FloatArray]:
    """The top silhouette's rings as an ENU footprint ``(n, 2)`` each.

    An outline pixel sees a roof edge at some height ``h``: its ray cut at ``z = h`` gives
    the footprint corner, and the model's height there (the top of the side views' solid)
    must be ``h`` again, starting from ``h_start`` (the top of what the top view sees of the
    side views' solid). Each corner iterates that to a fixed point, so a lower wing is put
    at its own roof height instead of being shrunk onto the highest roof's plane. Where two
    roofs meet, the outline belongs to the higher one, so the height is the highest within
    two pixels' ground distance of the corner.
    """
    r = top.pose.world_from_camera()
    ox, oy, oz = top.pose.pos_enu_m
    fx = top.intrinsics.fx_px
    if h_start >= oz:
        raise ModelInputError(
            f"top: the building ({h_start - ground_z_m:.1f} m) reaches the camera ({oz:.1f} m)"
        )
    out: list[FloatArray] = []
    for ring in _normalised_rings(top):
        pts: list[tuple[float, float]] = []
        for xn, yn in ring.tolist():
            dx = r[0, 0] * xn + r[0, 1] * yn + r[0, 2]
            dy = r[1, 0] * xn + r[1, 1] * yn + r[1, 2]
            dz = r[2, 0] * xn + r[2, 1] * yn + r[2, 2]
            if dz >= 0.0:
                raise ModelInputError("top: part of the silhouette is at or above the horizon")
            h = h_start
            x, y = ox, oy
            for _ in range(p.max_iterations):
                t = (oz - h) / -dz
                x, y = ox + t * dx, oy + t * dy
                new_h = _height_near(
                    side, x, y, radius_m=2.0 * (oz - h) / fx, z_top=h_start, z_bottom=ground_z_m
                )
                if new_h is None:
                    break
                done = abs(new_h - h) < p.tolerance_m
                h = new_h
                if done:
                    break
            t = (oz - h) / -dz
            pts.append((ox + t * dx, oy + t * dy))
        out.append(np.array(pts, dtype=np.float64))
    return out


def _height_near(
    solid: Any, x: float, y: float, *, radius_m: float, z_top: float, z_bottom: float
) -> float | None:
    """Highest top surface of ``solid`` over ``(x, y)`` and four points ``radius_m`` away."""
    best: float | None = None
    for ex, ey in ((0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)):
        px, py = x + ex * radius_m, y + ey * radius_m
        hits = solid.ray_cast((px, py, z_top + 1.0), (px, py, z_bottom - 1.0))
        if hits:
            z = float(hits[0].position[2])
            best = z if best is None else max(best, z)
    return best


def _prism(rings: Sequence[FloatArray], base_z_m: float, top_z_m: float) -> Any:
    import manifold3d  # noqa: PLC0415

    section = manifold3d.CrossSection(list(rings), manifold3d.FillRule.EvenOdd)
    return section.extrude(top_z_m - base_z_m).translate((0.0, 0.0, base_z_m))


def central_shape(shapes: tuple[Shape, ...], intrinsics: Intrinsics) -> Shape | None:
    """The shape a photo is centred on: the one whose centroid is nearest the principal
    point for its size (the distance over the square root of its area), so a building the
    photo was aimed at wins over a larger one beside it, and a small one near the centre
    over a large one's far-off centroid."""
    if not shapes:
        return None
    return min(
        shapes,
        key=lambda s: (
            math.hypot(s.centroid_px[0] - intrinsics.cx_px, s.centroid_px[1] - intrinsics.cy_px)
            / math.sqrt(max(s.area_px, 1.0))
        ),
    )


def same_colour(
    shapes: tuple[Shape, ...], colour_rgb: tuple[int, int, int], *, hue_tolerance_deg: float
) -> tuple[Shape, ...]:
    """The shapes whose colour's hue is within ``hue_tolerance_deg`` of ``colour_rgb``'s."""
    return tuple(
        s for s in shapes if hue_distance_deg(s.colour_rgb, colour_rgb) <= hue_tolerance_deg
    )
