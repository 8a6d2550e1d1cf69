"""One function per thing a mission shows in Rerun: each logs at the stream's current time.

Coordinates: the world is ENU metres around home (x east, y north, z up); a fleet's is
around vehicle 1's home, and each vehicle's entities are in its own frame (around its own
home), placed at its home by `log_fleet_vehicle`. Image overlays are pixels. The
mission's pixel coordinates put pixel centres on integers (OpenCV's convention) while Rerun
puts the top-left pixel's centre at (0.5, 0.5), hence ``_PX``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import rerun as rr

from uavtool.camera import CameraPose, Intrinsics
from uavtool.view.paths import Paths
from uavtool.world import Scene, building_mesh

_PX = 0.5  # mission pixel (centre on integers) → Rerun pixel (centre at +0.5)
_UI = -1.0  # Rerun reads a negative radius as UI points: overlays keep their width when zoomed
_IMAGE_PLANE_M = 4.0  # how far from the camera the frustum draws each frame in 3D
_TAG_RGB = {"overview": (60, 140, 255), "top": (40, 200, 90), "front": (40, 200, 90)}
_TAG_RGB["right"] = _TAG_RGB["top"]
_POI_TAG_RGB = (255, 160, 40)
_MODEL_RGBA = (250, 250, 250, 255)
_ROUTE_RGB = (255, 220, 0)
_MATCH_RGB = (0, 230, 80)
_CANDIDATE_RGB = (255, 140, 0)
_VECTOR_RGB = (0, 255, 255)  # shapes are drawn in one bright colour: in their own colour
# they vanish against the roofs they outline


_FLEET_RGB = (
    _ROUTE_RGB,
    (0, 200, 255),
    (255, 90, 200),
    (120, 230, 90),
    (255, 140, 40),
    (170, 130, 255),
)


def vehicle_rgb(sysid: int) -> tuple[int, int, int]:
    """The colour of a fleet's vehicle ``sysid`` (its route, its marker): vehicle 1's is the
    route colour of one vehicle, the others' stand apart from it and from each other."""
    return _FLEET_RGB[(sysid - 1) % len(_FLEET_RGB)]


def log_axes(rec: rr.RecordingStream, paths: Paths) -> None:
    """The world's axes (ENU, z up); static."""
    rec.log(paths.world, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)


def log_world(rec: rr.RecordingStream, paths: Paths) -> None:
    """The world's axes (ENU, z up) and the vehicle's marker; static."""
    log_axes(rec, paths)
    rec.log(
        paths.vehicle_body,
        rr.Boxes3D(half_sizes=[[0.6, 0.6, 0.15]], colors=[(230, 230, 230)]),
        rr.Arrows3D(vectors=[[1.6, 0.0, 0.0]], colors=[(255, 60, 60)]),
        static=True,
    )


def log_fleet_vehicle(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    home_en_m: tuple[float, float],
    rgb: tuple[int, int, int],
) -> None:
    """A fleet's vehicle: its frame (ENU metres around its own home, as its telemetry)
    placed at its home in the fleet's frame, and its marker in its colour, named; static."""
    rec.log(paths.world, rr.Transform3D(translation=(*home_en_m, 0.0)), static=True)
    rec.log(
        paths.vehicle_body,
        rr.Boxes3D(
            half_sizes=[[0.6, 0.6, 0.15]], colors=[rgb], labels=[paths.uav], show_labels=True
        ),
        rr.Arrows3D(vectors=[[1.6, 0.0, 0.0]], colors=[(255, 60, 60)]),
        static=True,
    )


def vertex_normals(vertices_m: Any, faces: Any) -> Any:
    """Unit normals, (n, 3) float32: each vertex's faces' normals weighted by their area.

    trimesh's ``vertex_normals`` does the same through scipy's sparse matrices and logs a
    traceback when scipy is missing; scipy is not a dependency of ours.
    """
    v = np.asarray(vertices_m, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    area_normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    sums = np.zeros_like(v)
    for k in range(3):
        np.add.at(sums, f[:, k], area_normals)
    lengths = np.linalg.norm(sums, axis=1, keepdims=True)
    return (sums / np.where(lengths > 0.0, lengths, 1.0)).astype(np.float32)


def log_scene(rec: rr.RecordingStream, paths: Paths, *, scene: Scene) -> None:
    """The ground-truth buildings as meshes in their colours, and the ground; static."""
    xs: list[float] = [0.0]
    ys: list[float] = [0.0]
    for building in scene.buildings:
        mesh = building_mesh(building)
        rec.log(
            paths.building(building.name),
            rr.Mesh3D(
                vertex_positions=np.asarray(mesh.vertices, dtype=np.float32),
                triangle_indices=np.asarray(mesh.faces, dtype=np.uint32),
                vertex_normals=vertex_normals(mesh.vertices, mesh.faces),
                albedo_factor=(*building.color_rgb, 255),
            ),
            static=True,
        )
        for block in building.blocks:
            xs += [x for x, _ in block.footprint_enu_m]
            ys += [y for _, y in block.footprint_enu_m]
    margin_m = 15.0
    x0, x1, y0, y1 = min(xs) - margin_m, max(xs) + margin_m, min(ys) - margin_m, max(ys) + margin_m
    rec.log(
        paths.ground,
        rr.Mesh3D(
            vertex_positions=[[x0, y0, -0.05], [x1, y0, -0.05], [x1, y1, -0.05], [x0, y1, -0.05]],
            triangle_indices=[[0, 1, 2], [0, 2, 3]],
            albedo_factor=(*scene.ground_rgb, 255),
        ),
        static=True,
    )


def log_target(rec: rr.RecordingStream, paths: Paths, *, png: bytes) -> None:
    """The target picture (what the mission looks for); static."""
    rec.log(paths.target, rr.EncodedImage(contents=png, media_type="image/png"), static=True)


def log_picture(rec: rr.RecordingStream, paths: Paths, *, tag: str, png: bytes) -> None:
    """An image the mission made (a mosaic, a map), at the time it was made."""
    rec.log(paths.picture(tag), rr.EncodedImage(contents=png, media_type="image/png"))


def log_detections(
    rec: rr.RecordingStream, paths: Paths, *, detections: Sequence[Mapping[str, Any]]
) -> int:
    """A vision function's detections (``replay --vision``) over the latest frame: boxes,
    polygons and points, labelled with their scores. Returns how many were drawn."""
    base = f"{paths.overlay}/detections"
    boxes, box_labels, strips, strip_labels, points, point_labels = [], [], [], [], [], []
    for d in detections:
        label = " ".join(p for p in (str(d.get("label", "")), _score_text(d.get("score"))) if p)
        if "box_px" in d:
            boxes.append([float(v) for v in d["box_px"]])
            box_labels.append(label)
        if "polygon_px" in d:
            ring = [[float(x), float(y)] for x, y in d["polygon_px"]]
            strips.append([*ring, ring[0]])
            strip_labels.append(label)
        for x, y in d.get("points_px", ()):
            points.append([float(x), float(y)])
            point_labels.append(label)
    rec.log(
        f"{base}/boxes",
        rr.Boxes2D(array=boxes, array_format=rr.Box2DFormat.XYXY, labels=box_labels)
        if boxes
        else rr.Clear(recursive=False),
    )
    rec.log(
        f"{base}/polygons",
        rr.LineStrips2D(strips, labels=strip_labels) if strips else rr.Clear(recursive=False),
    )
    rec.log(
        f"{base}/points",
        rr.Points2D(points, labels=point_labels, radii=3.0)
        if points
        else rr.Clear(recursive=False),
    )
    return len(detections)


def _score_text(score: object) -> str:
    return f"{score:.2f}" if isinstance(score, (int, float)) else ""


def log_photo(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    pose: CameraPose,
    intrinsics: Intrinsics,
    png: bytes | None,
) -> None:
    """The camera where it took a photo (frustum) with the frame; clears the last overlay."""
    rotation = pose.world_from_camera()
    rec.log(
        paths.camera,
        rr.Transform3D(translation=pose.pos_enu_m, mat3x3=rotation),
    )
    rec.log(
        paths.image,
        rr.Pinhole(
            focal_length=[intrinsics.fx_px, intrinsics.fy_px],
            principal_point=[intrinsics.cx_px + _PX, intrinsics.cy_px + _PX],
            width=intrinsics.width_px,
            height=intrinsics.height_px,
            image_plane_distance=_IMAGE_PLANE_M,
        ),
    )
    if png is not None:
        rec.log(paths.image, rr.EncodedImage(contents=png, media_type="image/png"))
    rec.log(paths.overlay, rr.Clear(recursive=True))


def log_photo_positions(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    positions_enu_m: Sequence[Sequence[float]],
    tags: Sequence[str],
) -> None:
    """Every photo position so far, labelled with its tag (the paper's Fig. 24–25)."""
    colours = [_TAG_RGB.get(tag, _POI_TAG_RGB) for tag in tags]
    rec.log(
        paths.photos,
        rr.Points3D(
            positions=np.asarray(positions_enu_m, dtype=np.float64).reshape(-1, 3),
            labels=list(tags),
            colors=colours,
            radii=0.6,
            show_labels=True,
        ),
    )


def shape_strips(
    shapes: Sequence[Mapping[str, Any]],
) -> tuple[list[npt.NDArray[np.float64]], list[tuple[int, int, int]]]:
    """Closed outlines (and holes) of the shapes in Rerun pixels, with each one's colour."""
    strips: list[npt.NDArray[np.float64]] = []
    colours: list[tuple[int, int, int]] = []
    for shape in shapes:
        rgb = _rgb(shape.get("colour_rgb"))
        for ring in [shape.get("polygon_px") or [], *(shape.get("holes_px") or [])]:
            if len(ring) < 2:
                continue
            pts = np.asarray(ring, dtype=np.float64) + _PX
            strips.append(np.vstack([pts, pts[:1]]))
            colours.append(rgb)
    return strips, colours


def log_shapes(
    rec: rr.RecordingStream, path: str, *, shapes: Sequence[Mapping[str, Any]], static: bool = False
) -> None:
    """The vectorized shapes of one frame as closed 2D line strips with their corners."""
    strips, _ = shape_strips(shapes)
    corners = np.vstack([s[:-1] for s in strips]) if strips else np.zeros((0, 2))
    rec.log(
        path,
        rr.LineStrips2D(strips, colors=[_VECTOR_RGB], radii=1.5 * _UI, draw_order=20.0),
        rr.Points2D(corners, colors=[_VECTOR_RGB], radii=2.5 * _UI, draw_order=21.0),
        static=static,
    )


def log_image_pois(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    centroids_px: Sequence[Sequence[float]],
    labels: Sequence[str],
) -> None:
    """Points of interest marked on the overview frame (at their shapes' centroids)."""
    pts = np.asarray(centroids_px, dtype=np.float64).reshape(-1, 2) + _PX
    rec.log(
        paths.image_pois,
        rr.Points2D(
            pts, labels=list(labels), radii=5.0 * _UI, colors=[(255, 255, 255)], draw_order=30.0
        ),
    )


def log_match(
    rec: rr.RecordingStream, paths: Paths, *, shape: Mapping[str, Any], label: str, matched: bool
) -> None:
    """The shape the recognizer picked in this frame: green if it matched, orange if not."""
    strips, _ = shape_strips([shape])
    colour = _MATCH_RGB if matched else _CANDIDATE_RGB
    rec.log(
        paths.match,
        rr.LineStrips2D(
            strips, colors=[colour], radii=3.0 * _UI, labels=[label] * len(strips), draw_order=25.0
        ),
    )


def log_pois(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    positions_en_m: Sequence[Sequence[float]],
    labels: Sequence[str],
    colours_rgb: Sequence[Sequence[int]],
    matched: Sequence[bool],
    height_m: float,
) -> None:
    """Points of interest over the ground, as the mission located them; the match bigger."""
    pos = [(float(e), float(n), height_m) for e, n in positions_en_m]
    rec.log(
        paths.pois,
        rr.Points3D(
            positions=np.asarray(pos).reshape(-1, 3),
            labels=list(labels),
            colors=[_rgb(c) for c in colours_rgb],
            radii=[1.4 if m else 0.8 for m in matched],
            show_labels=True,
        ),
    )


def log_viewpoints(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    footprint_en_m: Sequence[Sequence[float]],
    viewpoints: Sequence[Mapping[str, Any]],
) -> None:
    """The planned top/front/right viewpoints (where, and where the camera looks) and the
    building footprint they were planned around. Failed viewpoints are not drawn."""
    ring = [(float(e), float(n), 0.15) for e, n in footprint_en_m]
    if ring:
        rec.log(
            paths.footprint, rr.LineStrips3D([[*ring, ring[0]]], colors=[_MATCH_RGB], radii=0.12)
        )
    good = [v for v in viewpoints if "pos_enu_m" in v]
    if not good:
        return
    origins = [tuple(float(c) for c in v["pos_enu_m"]) for v in good]
    looks = [_look_enu(float(v["heading_deg"]), float(v.get("pitch_deg", 0.0))) for v in good]
    labels = [_viewpoint_label(v) for v in good]
    rec.log(
        paths.viewpoints,
        rr.Points3D(
            positions=origins, labels=labels, colors=[_MATCH_RGB], radii=0.5, show_labels=True
        ),
        rr.Arrows3D(
            origins=origins,
            vectors=[(3.0 * x, 3.0 * y, 3.0 * z) for x, y, z in looks],
            colors=[_MATCH_RGB],
        ),
    )


def log_model(
    rec: rr.RecordingStream,
    paths: Paths,
    *,
    vertices_m: Sequence[Sequence[float]],
    faces: Sequence[Sequence[int]],
    offset_enu_m: tuple[float, float, float],
    label: str,
) -> None:
    """The built 3D model, moved by ``offset_enu_m`` so it stands next to the true building."""
    verts = np.asarray(vertices_m, dtype=np.float32).reshape(-1, 3)
    rec.log(paths.model, rr.Transform3D(translation=offset_enu_m))
    rec.log(
        paths.model_mesh,
        rr.Mesh3D(
            vertex_positions=verts,
            triangle_indices=np.asarray(faces, dtype=np.uint32).reshape(-1, 3),
            albedo_factor=_MODEL_RGBA,
        ),
    )
    if len(verts):
        top = (float(verts[:, 0].mean()), float(verts[:, 1].mean()), float(verts[:, 2].max()) + 1.0)
        rec.log(
            f"{paths.model}/label", rr.Points3D([top], labels=[label], radii=0.3, show_labels=True)
        )


def log_route_chunk(
    rec: rr.RecordingStream,
    path: str,
    *,
    positions_enu_m: npt.NDArray[np.float64],
    rgb: tuple[int, int, int] | None = None,
) -> None:
    """One piece of the route flown so far, in ``rgb`` (None: the route's colour); pieces
    are separate entities so all stay shown."""
    colour = _ROUTE_RGB if rgb is None else rgb
    rec.log(path, rr.LineStrips3D([positions_enu_m], colors=[colour], radii=0.15))


def log_text(rec: rr.RecordingStream, path: str, *, text: str, level: str) -> None:
    """One line of a text log; ``level`` one of Rerun's (``INFO``, ``WARN``, ``ERROR`` …)."""
    rec.log(path, rr.TextLog(text, level=level))


def log_scalar(rec: rr.RecordingStream, path: str, *, value: float) -> None:
    rec.log(path, rr.Scalars([value]))


def _rgb(value: object) -> tuple[int, int, int]:
    if isinstance(value, Sequence) and len(value) >= 3:
        return (int(value[0]), int(value[1]), int(value[2]))
    return (200, 200, 200)


def _look_enu(heading_deg: float, pitch_deg: float) -> tuple[float, float, float]:
    h, p = math.radians(heading_deg), math.radians(pitch_deg)
    return (math.sin(h) * math.cos(p), math.cos(h) * math.cos(p), math.sin(p))


def _viewpoint_label(v: Mapping[str, Any]) -> str:
    label = str(v.get("name", "?"))
    fallback = v.get("fallback")
    return f"{label} ({fallback})" if fallback else label
