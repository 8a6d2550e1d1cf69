"""Foxglove's Protobuf schemas: our value types to and from `foxglove.*` messages.

Foxglove Studio and Rerun's MCAP importer display these natively. Each message's
``timestamp`` is the message's log time, so transforms, images and calibrations line up on
one clock in every viewer.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from foxglove_schemas_protobuf.CameraCalibration_pb2 import (
    CameraCalibration as PbCameraCalibration,
)
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage as PbCompressedImage
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform as PbFrameTransform
from foxglove_schemas_protobuf.LocationFix_pb2 import LocationFix as PbLocationFix
from foxglove_schemas_protobuf.Log_pb2 import Log as PbLog
from foxglove_schemas_protobuf.PosesInFrame_pb2 import PosesInFrame as PbPosesInFrame
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate as PbSceneUpdate
from google.protobuf.descriptor_pb2 import FileDescriptorSet  # type: ignore[import-untyped]

from uavtool.glb import mesh_glb
from uavtool.png import rgb_png
from uavtool.recording.scene import decode_markers, encode_markers
from uavtool.recording.values import (
    CameraCalibration,
    CompressedImage,
    FrameTransform,
    LocationFix,
    LogEntry,
    LogLevel,
    Model3D,
    Pose,
    PosesInFrame,
    RgbImage,
    SceneMarkers,
)

FoxgloveValue = (
    CompressedImage
    | CameraCalibration
    | FrameTransform
    | LocationFix
    | PosesInFrame
    | LogEntry
    | Model3D
    | SceneMarkers
)

_GLB_MEDIA_TYPE = "model/gltf-binary"

# our value type -> the Protobuf class that carries it
_PB_CLASS: dict[type, Any] = {
    CompressedImage: PbCompressedImage,
    CameraCalibration: PbCameraCalibration,
    FrameTransform: PbFrameTransform,
    LocationFix: PbLocationFix,
    PosesInFrame: PbPosesInFrame,
    LogEntry: PbLog,
    Model3D: PbSceneUpdate,
    SceneMarkers: PbSceneUpdate,  # one schema, two views: a model, or markers
}
_SCHEMA_DATA: dict[type, bytes] = {}
SCHEMA_NAMES: frozenset[str] = frozenset(c.DESCRIPTOR.full_name for c in _PB_CLASS.values())


def schema_name(value_type: type) -> str:
    """The Protobuf full name (e.g. ``foxglove.CompressedImage``) for one of our value types."""
    return str(_PB_CLASS[value_type].DESCRIPTOR.full_name)


def schema_data(value_type: type) -> bytes:
    """The serialized FileDescriptorSet MCAP stores as the channel's schema."""
    data = _SCHEMA_DATA.get(value_type)
    if data is None:
        data = _SCHEMA_DATA[value_type] = file_descriptor_set(_PB_CLASS[value_type])
    return data


def file_descriptor_set(pb_class: Any) -> bytes:
    """mcap_protobuf's ``build_file_descriptor_set(pb_class)``, serialized deterministically:
    the class's file after every file it depends on, each once. Its module imports mcap's
    writer (~15 ms, of a writer process that needs none of it), so the walk is made here; a
    test holds the two byte-identical for every schema uavtool writes."""
    files = FileDescriptorSet()
    seen: set[str] = set()

    def add(file: Any) -> None:
        for dep in file.dependencies:
            if dep.name not in seen:
                seen.add(dep.name)
                add(dep)
        file.CopyToProto(files.file.add())

    add(pb_class.DESCRIPTOR.file)
    return bytes(files.SerializeToString(deterministic=True))


def deferred(value: FoxgloveValue) -> bool:
    """Whether encoding ``value`` makes something heavy first (a frame's PNG, a model's GLB):
    a writer process does that off the flight's path."""
    return (isinstance(value, CompressedImage) and value.raw is not None) or (
        isinstance(value, Model3D) and value.mesh is not None
    )


def _png(image: RgbImage) -> bytes:
    return rgb_png(image.pixels, image.height_px, image.width_px)


_MODEL_GREY = (0.8, 0.8, 0.8, 1.0)


def _unknown_covariance(pb: Any) -> None:
    """A fix without an accuracy estimate: nine zeros, COVARIANCE_TYPE_UNKNOWN (0), which
    Foxglove's JSON schema asks for (exactly nine values)."""
    pb.position_covariance.extend((0.0,) * 9)
    pb.position_covariance_type = 0


def _stamp(pb: Any, t_ns: int) -> None:
    pb.timestamp.seconds, pb.timestamp.nanos = divmod(t_ns, 1_000_000_000)


def _pose_pb(pose: Pose, pb: Any) -> None:
    pb.position.x, pb.position.y, pb.position.z = pose.position_m
    q = pb.orientation
    q.x, q.y, q.z, q.w = pose.orientation_xyzw


def _pose(pb: Any) -> Pose:
    p, q = pb.position, pb.orientation
    return Pose((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))


def encode(value: FoxgloveValue, t_ns: int) -> bytes:
    """Serialize ``value`` as its Foxglove message with ``timestamp`` = ``t_ns``."""
    pb: Any = _PB_CLASS[type(value)]()
    if isinstance(value, CompressedImage):
        _stamp(pb, t_ns)
        data = value.data if value.raw is None else _png(value.raw)
        pb.frame_id, pb.data, pb.format = value.frame_id, data, value.format
    elif isinstance(value, CameraCalibration):
        _stamp(pb, t_ns)
        pb.frame_id, pb.width, pb.height = value.frame_id, value.width_px, value.height_px
        pb.distortion_model = value.distortion_model
        pb.D.extend(value.d)
        pb.K.extend(value.k)
        pb.R.extend(value.r)
        pb.P.extend(value.p)
    elif isinstance(value, FrameTransform):
        _stamp(pb, t_ns)
        pb.parent_frame_id, pb.child_frame_id = value.parent_frame_id, value.child_frame_id
        pb.translation.x, pb.translation.y, pb.translation.z = value.translation_m
        r = pb.rotation
        r.x, r.y, r.z, r.w = value.rotation_xyzw
    elif isinstance(value, LocationFix):
        _stamp(pb, t_ns)
        pb.frame_id = value.frame_id
        pb.latitude, pb.longitude, pb.altitude = (
            value.latitude_deg,
            value.longitude_deg,
            value.altitude_m,
        )
        c = pb.color
        c.r, c.g, c.b, c.a = value.color_rgba
        _unknown_covariance(pb)
    elif isinstance(value, PosesInFrame):
        _stamp(pb, t_ns)
        pb.frame_id = value.frame_id
        for pose in value.poses:
            _pose_pb(pose, pb.poses.add())
    elif isinstance(value, LogEntry):
        _stamp(pb, t_ns)
        pb.level = int(value.level)
        pb.message, pb.name, pb.file, pb.line = value.message, value.name, value.file, value.line
    elif isinstance(value, SceneMarkers):
        encode_markers(value, pb, t_ns)
    else:  # Model3D: one scene entity holding one embedded glTF model
        entity = pb.entities.add()
        _stamp(entity, t_ns)
        entity.frame_id, entity.id = value.frame_id, value.entity_id
        entity.lifetime.SetInParent()  # 0: until replaced
        model = entity.models.add()
        _pose_pb(value.pose, model.pose)
        model.scale.x = model.scale.y = model.scale.z = 1.0
        c = model.color  # used only with override_color (off): the model's own grey
        c.r, c.g, c.b, c.a = _MODEL_GREY
        mesh = value.mesh
        glb = value.glb if mesh is None else mesh_glb(mesh.vertices_m, mesh.faces)
        model.media_type, model.data = _GLB_MEDIA_TYPE, glb
    return bytes(pb.SerializeToString(deterministic=True))


class VehicleEncoder:
    """The vehicle's pose (`PosesInFrame` of `Pose.from_enu_heading`) and WGS-84 fix
    (`LocationFix` with its defaults) as `encode` writes them, byte for byte, in a third of
    the time: one Protobuf message of each is filled again for every sample (a flight writes
    thousands), and the same fields are set every time, so nothing of the last one stays."""

    def __init__(self) -> None:
        pose = Pose.from_enu_heading((0.0, 0.0, 0.0), 0.0)
        self._poses: Any = _PB_CLASS[PosesInFrame]()
        self._poses.frame_id = PosesInFrame((pose,)).frame_id
        self._pose: Any = self._poses.poses.add()
        fix = LocationFix(0.0, 0.0, 0.0)
        self._fix: Any = _PB_CLASS[LocationFix]()
        self._fix.frame_id = fix.frame_id
        c = self._fix.color
        c.r, c.g, c.b, c.a = fix.color_rgba
        _unknown_covariance(self._fix)

    def pose(self, pos_enu_m: tuple[float, float, float], heading_deg: float, t_ns: int) -> bytes:
        """``encode(PosesInFrame((Pose.from_enu_heading(pos_enu_m, heading_deg),)), t_ns)``."""
        _stamp(self._poses, t_ns)
        _pose_pb(Pose.from_enu_heading(pos_enu_m, heading_deg), self._pose)
        return bytes(self._poses.SerializeToString(deterministic=True))

    def fix(self, latitude_deg: float, longitude_deg: float, altitude_m: float, t_ns: int) -> bytes:
        """``encode(LocationFix(latitude_deg, longitude_deg, altitude_m), t_ns)``."""
        pb = self._fix
        _stamp(pb, t_ns)
        pb.latitude, pb.longitude, pb.altitude = latitude_deg, longitude_deg, altitude_m
        return bytes(pb.SerializeToString(deterministic=True))


def decode(name: str, data: bytes) -> FoxgloveValue:
    """Parse a message of Foxglove schema ``name``; `KeyError` if it is not one of ours."""
    cls = next(c for v, c in _PB_CLASS.items() if schema_name(v) == name)
    pb: Any = cls.FromString(data)
    if cls is PbCompressedImage:
        return CompressedImage(pb.data, pb.format, pb.frame_id)
    if cls is PbCameraCalibration:
        return CameraCalibration(
            pb.width,
            pb.height,
            tuple(pb.K),
            tuple(pb.P),
            tuple(pb.R),
            tuple(pb.D),
            pb.distortion_model,
            pb.frame_id,
        )
    if cls is PbFrameTransform:
        t, r = pb.translation, pb.rotation
        return FrameTransform(
            pb.parent_frame_id, pb.child_frame_id, (t.x, t.y, t.z), (r.x, r.y, r.z, r.w)
        )
    if cls is PbLocationFix:
        fix = LocationFix(pb.latitude, pb.longitude, pb.altitude, pb.frame_id)
        if pb.HasField("color"):  # older recordings have none: the default colour
            c = pb.color
            fix = dataclasses.replace(fix, color_rgba=(c.r, c.g, c.b, c.a))
        return fix
    if cls is PbPosesInFrame:
        return PosesInFrame(tuple(_pose(p) for p in pb.poses), pb.frame_id)
    if cls is PbLog:
        return LogEntry(LogLevel(pb.level), pb.message, pb.name, pb.file, pb.line)
    if not any(e.models for e in pb.entities):
        return decode_markers(pb)
    entity = pb.entities[0]
    model = entity.models[0]
    return Model3D(model.data, entity.id, entity.frame_id, _pose(model.pose))
