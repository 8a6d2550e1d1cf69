"""`SceneMarkers` to and from `foxglove.SceneUpdate`: lines, arrows, spheres and labels that
Foxglove's and Lichtblick's 3D panels draw without any setup (the route, the photo poses, the
points of interest, the viewpoints)."""

from __future__ import annotations

from typing import Any

from uavtool.recording.values import Pose, SceneEntity, SceneMarkers, Vec3

_LINE_STRIP = 0  # foxglove.LinePrimitive.Type.LINE_STRIP


def _xyz(pb: Any, p: Vec3) -> None:
    pb.x, pb.y, pb.z = p


def _colour(pb: Any, rgba: tuple[float, float, float, float]) -> None:
    pb.r, pb.g, pb.b, pb.a = rgba


def _pose(pb: Any, pose: Pose) -> None:
    _xyz(pb.position, pose.position_m)
    q = pb.orientation
    q.x, q.y, q.z, q.w = pose.orientation_xyzw


def encode_markers(value: SceneMarkers, pb: Any, t_ns: int) -> None:
    """Fill the `foxglove.SceneUpdate` ``pb`` with ``value``'s entities, stamped ``t_ns``."""
    for e in value.entities:
        entity = pb.entities.add()
        entity.timestamp.seconds, entity.timestamp.nanos = divmod(t_ns, 1_000_000_000)
        entity.frame_id, entity.id = e.frame_id, e.entity_id
        entity.lifetime.SetInParent()  # 0: until replaced (Foxglove's JSON schema requires it)
        if e.line_m:
            line = entity.lines.add()
            _pose(line.pose, Pose((0.0, 0.0, 0.0)))  # the points are in the entity's frame
            line.type, line.thickness, line.scale_invariant = _LINE_STRIP, 2.0, True
            _colour(line.color, e.colour_rgba)
            for p in e.line_m:
                _xyz(line.points.add(), p)
        for pose in e.arrows:
            arrow = entity.arrows.add()
            _pose(arrow.pose, pose)
            arrow.shaft_length, arrow.shaft_diameter = e.size_m, e.size_m / 8
            arrow.head_length, arrow.head_diameter = e.size_m / 3, e.size_m / 4
            _colour(arrow.color, e.colour_rgba)
        for centre in e.spheres_m:
            sphere = entity.spheres.add()
            _pose(sphere.pose, Pose(centre))
            _xyz(sphere.size, (e.size_m, e.size_m, e.size_m))
            _colour(sphere.color, e.colour_rgba)
        for at, text in e.texts:
            label = entity.texts.add()
            _pose(label.pose, Pose(at))
            label.billboard, label.font_size, label.scale_invariant = True, 14.0, True
            label.text = text
            _colour(label.color, e.colour_rgba)


def _p(pb: Any) -> Vec3:
    return (pb.x, pb.y, pb.z)


def _q(pb: Any) -> Pose:
    o = pb.orientation
    return Pose(_p(pb.position), (o.x, o.y, o.z, o.w))


def decode_markers(pb: Any) -> SceneMarkers:
    """The `SceneMarkers` a `foxglove.SceneUpdate` of marker entities holds."""
    entities = []
    for e in pb.entities:
        colours = [x.color for x in (*e.lines, *e.arrows, *e.spheres, *e.texts)]
        c = colours[0] if colours else None
        size = e.arrows[0].shaft_length if e.arrows else e.spheres[0].size.x if e.spheres else 1.0
        entities.append(
            SceneEntity(
                e.id,
                (c.r, c.g, c.b, c.a) if c is not None else (0.0, 0.0, 0.0, 0.0),
                tuple(_p(p) for line in e.lines for p in line.points),
                tuple(_q(a.pose) for a in e.arrows),
                tuple(_p(s.pose.position) for s in e.spheres),
                tuple((_p(t.pose.position), t.text) for t in e.texts),
                size,
                e.frame_id,
            )
        )
    return SceneMarkers(tuple(entities))
