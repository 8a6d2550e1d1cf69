"""The values a recording holds, as small immutable types shared by the writer and reader.

Writing a value and reading it back gives an equal value: these types are both the write API
and what the reader decodes to. Times are not part of the values; they travel alongside in
`Entry` (``log_time_ns`` = receive time, ``publish_time_ns`` = the writer's publish time,
equal to the log time in what ``uavtool fly`` records).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum, IntEnum
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # numpy with it: a writer process needs none of it
    from uavtool.camera import CameraPose, Intrinsics

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

_MAVLINK_V2_STX = 0xFD
_MAVLINK_V1_STX = 0xFE


class Direction(Enum):
    """Which way a MAVLink frame crossed the link, seen from the ground-station side."""

    IN = "in"  # vehicle -> ground station (received by the link)
    OUT = "out"  # ground station -> vehicle (sent by the link)


class LogLevel(IntEnum):
    """`foxglove.Log` levels."""

    UNKNOWN = 0
    DEBUG = 1
    INFO = 2
    WARNING = 3
    ERROR = 4
    FATAL = 5


@dataclass(frozen=True, slots=True)
class MavlinkFrame:
    """One MAVLink frame exactly as it crossed the link (v1 or v2, signed or not)."""

    direction: Direction
    data: bytes

    @property
    def version(self) -> int:
        """1 or 2 (0 when the frame does not start with a MAVLink magic byte)."""
        if not self.data:
            return 0
        return {_MAVLINK_V2_STX: 2, _MAVLINK_V1_STX: 1}.get(self.data[0], 0)

    @property
    def seq(self) -> int:
        return self.data[4] if self.version == 2 else self.data[2]

    @property
    def sysid(self) -> int:
        return self.data[5] if self.version == 2 else self.data[3]

    @property
    def compid(self) -> int:
        return self.data[6] if self.version == 2 else self.data[4]

    @property
    def msgid(self) -> int:
        if self.version == 2:
            return int.from_bytes(self.data[7:10], "little")
        return self.data[5]


@dataclass(frozen=True, slots=True)
class JsonDocument:
    """A JSON message: the schema's name and the decoded object."""

    schema_name: str
    payload: Mapping[str, Any]


@dataclass(frozen=True, slots=True)
class RgbImage:
    """A frame's raw pixels: ``height_px`` rows of ``width_px`` RGB pixels, 3 bytes each."""

    pixels: bytes
    height_px: int
    width_px: int


@dataclass(frozen=True, slots=True)
class CompressedImage:
    """A camera frame as encoded bytes (PNG by default: lossless).

    Given ``raw`` pixels instead (``data`` empty, ``format`` "png"), the writer encodes them
    (:func:`uavtool.images.png_encode`) where it encodes the message — in a writer process,
    off the flight's path — and the frame reads back with those bytes as ``data``."""

    data: bytes
    format: str = "png"
    frame_id: str = "camera"
    raw: RgbImage | None = None


@dataclass(frozen=True, slots=True)
class CameraCalibration:
    """Pinhole calibration in Foxglove/ROS layout (row-major K 3×3, R 3×3, P 3×4)."""

    width_px: int
    height_px: int
    k: tuple[float, ...]
    p: tuple[float, ...]
    r: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    d: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)
    distortion_model: str = "plumb_bob"
    frame_id: str = "camera"

    @classmethod
    def from_intrinsics(
        cls, intrinsics: Intrinsics, *, frame_id: str = "camera"
    ) -> CameraCalibration:
        """The calibration of a `uavtool.camera.Intrinsics` camera (no distortion)."""
        i = intrinsics
        k = (i.fx_px, 0.0, i.cx_px, 0.0, i.fy_px, i.cy_px, 0.0, 0.0, 1.0)
        p = (i.fx_px, 0.0, i.cx_px, 0.0, 0.0, i.fy_px, i.cy_px, 0.0, 0.0, 0.0, 1.0, 0.0)
        return cls(i.width_px, i.height_px, k, p, frame_id=frame_id)


@dataclass(frozen=True, slots=True)
class FrameTransform:
    """Where ``child`` sits in ``parent``: translation (m) and rotation quaternion (x, y, z, w)."""

    parent_frame_id: str
    child_frame_id: str
    translation_m: Vec3
    rotation_xyzw: Quat

    @classmethod
    def from_camera_pose(
        cls, pose: CameraPose, *, parent_frame_id: str = "world", child_frame_id: str = "camera"
    ) -> FrameTransform:
        """The camera's optical frame (x right, y down, z forward) in world ENU."""
        rot = pose.world_from_camera()
        matrix = tuple(tuple(float(v) for v in row) for row in rot)
        return cls(parent_frame_id, child_frame_id, pose.pos_enu_m, quaternion_from_matrix(matrix))


@dataclass(frozen=True, slots=True)
class LocationFix:
    """A WGS-84 position (degrees, metres above the ellipsoid or AMSL as the source gives)."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    frame_id: str = "vehicle"
    color_rgba: tuple[float, float, float, float] = (1.0, 0.55, 0.0, 1.0)
    """How a map draws it (0–1 each; orange, as the route): Rerun's MCAP importer needs one."""


@dataclass(frozen=True, slots=True)
class Pose:
    """A position (m) and orientation quaternion (x, y, z, w)."""

    position_m: Vec3
    orientation_xyzw: Quat = (0.0, 0.0, 0.0, 1.0)

    @classmethod
    def from_enu_heading(cls, pos_enu_m: Vec3, heading_deg: float) -> Pose:
        """A vehicle pose in ENU from its heading (deg clockwise from north), level attitude."""
        # ENU yaw is counter-clockwise from east: yaw = 90° − heading.
        half = math.radians(90.0 - heading_deg) / 2.0
        return cls(pos_enu_m, (0.0, 0.0, math.sin(half), math.cos(half)))


@dataclass(frozen=True, slots=True)
class PosesInFrame:
    """Poses in one frame (e.g. the vehicle's pose, or a route)."""

    poses: tuple[Pose, ...]
    frame_id: str = "world"


@dataclass(frozen=True, slots=True)
class LogEntry:
    """A mission event or log line (`foxglove.Log`)."""

    level: LogLevel
    message: str
    name: str = "mission"
    file: str = ""
    line: int = 0


@dataclass(frozen=True, slots=True)
class TriangleMesh:
    """Triangles in metres: ``vertices_m`` ``(n, 3)`` and ``faces`` ``(m, 3)``, indices into
    them, counter-clockwise seen from outside."""

    vertices_m: tuple[Vec3, ...]
    faces: tuple[tuple[int, int, int], ...]


@dataclass(frozen=True, slots=True)
class Model3D:
    """A 3D model as GLB bytes, placed at ``pose`` in ``frame_id``.

    Given a ``mesh`` instead (``glb`` empty), the writer encodes it as GLB
    (:func:`uavtool.glb.mesh_glb`, flat light-grey faces) where it encodes the message — in a
    writer process, off the flight's path — and the model reads back with those bytes as
    ``glb``."""

    glb: bytes
    entity_id: str = "model"
    frame_id: str = "world"
    pose: Pose = Pose((0.0, 0.0, 0.0))
    mesh: TriangleMesh | None = None


@dataclass(frozen=True, slots=True)
class SceneEntity:
    """Markers a 3D panel draws (`foxglove.SceneEntity`), in ``frame_id``, one colour.

    ``line_m`` : (n, 3) points of one polyline; ``arrows`` : poses whose x axis points the
    way; ``spheres_m`` : (k, 3) centres of spheres ``size_m`` across; ``texts`` : labels.
    """

    entity_id: str
    colour_rgba: tuple[float, float, float, float]
    line_m: tuple[Vec3, ...] = ()
    arrows: tuple[Pose, ...] = ()
    spheres_m: tuple[Vec3, ...] = ()
    texts: tuple[tuple[Vec3, str], ...] = ()
    size_m: float = 1.0
    frame_id: str = "world"


@dataclass(frozen=True, slots=True)
class SceneMarkers:
    """A `foxglove.SceneUpdate` of marker entities; each replaces the entity of its id."""

    entities: tuple[SceneEntity, ...]


FOXGLOVE_TYPES: frozenset[type] = frozenset(
    {
        CompressedImage,
        CameraCalibration,
        FrameTransform,
        LocationFix,
        PosesInFrame,
        LogEntry,
        Model3D,
        SceneMarkers,
    }
)
"""The values written as Foxglove messages (`uavtool.recording.foxglove` encodes them)."""

Value = (
    MavlinkFrame
    | JsonDocument
    | CompressedImage
    | CameraCalibration
    | FrameTransform
    | LocationFix
    | PosesInFrame
    | LogEntry
    | Model3D
    | SceneMarkers
)


@dataclass(frozen=True, slots=True)
class Entry:
    """One decoded message with its place in the recording."""

    topic: str
    log_time_ns: int
    publish_time_ns: int
    sequence: int
    value: Value


def quaternion_from_matrix(m: tuple[tuple[float, ...], ...]) -> Quat:
    """Unit quaternion (x, y, z, w) of a 3×3 rotation matrix (Shepperd's method, math only)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0) * 2.0
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4.0)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2.0
        q = (s / 4.0, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2.0
        q = ((m[0][1] + m[1][0]) / s, s / 4.0, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2.0
        q = ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4.0, (m[1][0] - m[0][1]) / s)
    return q
