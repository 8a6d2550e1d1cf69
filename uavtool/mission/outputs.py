"""What the mission produces: commands for the vehicle and camera (which the runner executes),
and results (vision, navigation, events, the outcome) which are recorded and compared on replay.
Every output is a small immutable value; ``id`` numbers a mission's commands from 1."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Any

from uavtool.nav import Viewpoint, ViewpointFailure
from uavtool.vision import Shape

Vec3 = tuple[float, float, float]


# --- commands ----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class SetMode:
    """Switch the autopilot to a mode by ArduCopter name (``GUIDED``, ``RTL``, ``LAND`` …)."""

    id: int
    mode: str


@dataclass(frozen=True, slots=True)
class Arm:
    id: int


@dataclass(frozen=True, slots=True)
class Takeoff:
    """Climb vertically to ``alt_m`` above home (GUIDED, armed)."""

    id: int
    alt_m: float


@dataclass(frozen=True, slots=True)
class GoTo:
    """Fly to ``pos_enu_m`` (z above home) and face ``heading_deg`` (None: keep heading)."""

    id: int
    pos_enu_m: Vec3
    heading_deg: float | None


@dataclass(frozen=True, slots=True)
class SetGimbal:
    """Point the camera: ``pitch_deg`` (−90 nadir, 0 horizontal), ``yaw_deg`` from the nose."""

    id: int
    pitch_deg: float
    yaw_deg: float = 0.0


@dataclass(frozen=True, slots=True)
class TakePhoto:
    """Take a photo now; the runner answers with a :class:`Photo` observation."""

    id: int
    tag: str


Command = SetMode | Arm | Takeoff | GoTo | SetGimbal | TakePhoto


# --- results -----------------------------------------------------------------------------------


class Level(Enum):
    INFO = "info"
    WARNING = "warning"
    ERROR = "error"


@dataclass(frozen=True, slots=True)
class Event:
    """Something worth telling a person (phase changes, findings, failures)."""

    level: Level
    text: str


@dataclass(frozen=True, slots=True)
class Shapes:
    """The shapes vectorized from frame ``frame_index``."""

    frame_index: int
    tag: str
    shapes: tuple[Shape, ...]


@dataclass(frozen=True, slots=True)
class PointOfInterest:
    """A building seen in the overview: where it is (ENU, the centre of its roof) and its
    colour. ``shape_index`` is its index in the overview's shapes; ``roof_m`` its roof height
    above home, measured from two overview photos (``roof_measured``) or assumed;
    ``extent_m`` the diagonal of its footprint's smallest rectangle."""

    index: int
    shape_index: int
    pos_en_m: tuple[float, float]
    colour_rgb: tuple[int, int, int]
    area_px: float
    roof_m: float
    roof_measured: bool
    extent_m: float


@dataclass(frozen=True, slots=True)
class Plan:
    """The points of interest and the order they will be visited in."""

    frame_index: int
    pois: tuple[PointOfInterest, ...]
    order: tuple[int, ...]
    route_m: float


@dataclass(frozen=True, slots=True)
class Recognition:
    """Frame ``frame_index`` at point of interest ``poi`` compared with the target.

    ``scores`` : one per shape of the frame; ``candidate`` the shape judged (the one the photo
    is centred on; −1 if none), ``score`` its score, ``matched`` the decision;
    ``mirror_score`` the candidate's score against the target's mirror image."""

    frame_index: int
    poi: int
    scores: tuple[float, ...]
    candidate: int
    score: float
    matched: bool
    mirror_score: float = 0.0


@dataclass(frozen=True, slots=True)
class Viewpoints:
    """The photo positions planned for the model. ``footprint_en_m`` is the target's
    estimated footprint they were planned around."""

    footprint_en_m: tuple[tuple[float, float], ...]
    top: Viewpoint
    front: Viewpoint | ViewpointFailure
    right: Viewpoint | ViewpointFailure


@dataclass(frozen=True, slots=True)
class DiagonalView:
    """The model from the top, front and right photos is open under ``open_beneath`` of its
    largest section (the side photos saw through under the building): the diagonal photo
    planned to carve what they could not see through, or why there is none."""

    open_beneath: float
    viewpoint: Viewpoint | ViewpointFailure


@dataclass(frozen=True, slots=True)
class ModelBuilt:
    """The 3D model (world ENU metres): a watertight triangle mesh as nested tuples (faces
    counter-clockwise seen from outside). A recording holds it as GLB too (``/mission/model``,
    :func:`uavtool.glb.mesh_glb`)."""

    vertices_m: tuple[tuple[float, float, float], ...]
    faces: tuple[tuple[int, int, int], ...]
    height_m: float
    volume_m3: float


class Status(Enum):
    """How a mission ended (``uavtool fly`` maps each to its exit code)."""

    COMPLETED = "completed"
    """The mission did all it set out to do, and the vehicle landed (the built-in mission:
    the target was found and its model built)."""
    PARTIAL = "partial"
    """The mission did part of its work (the built-in mission: the target was found but no
    model was built)."""
    NO_MATCH = "no-match"
    """The search ended without a match (what a mission looked for is not there)."""
    ABORTED = "aborted"
    """The mission gave up (a command refused, a position never reached …) and sent RTL."""
    TAKEOVER = "pilot-takeover"
    """Someone else changed the mode; the mission stopped commanding."""
    LINK_LOST = "link-lost"
    """The link stayed silent for too long."""
    CRASHED = "crashed"
    """The vehicle disarmed in the air (its crash check): it hit something."""


@dataclass(frozen=True, slots=True)
class Outcome:
    """How the mission ended; the last output. The built-in mission also says what it found:
    ``visited`` lists points of interest in the order photographed; ``matched_poi`` is −1
    when none matched (other missions leave these at their defaults)."""

    status: Status
    reason: str
    visited: tuple[int, ...] = ()
    matched_poi: int = -1
    match_score: float = 0.0
    model_built: bool = False


@dataclass(frozen=True, slots=True)
class Result:
    """Anything a mission found, as JSON values (numbers, strings, lists, objects) under a
    ``tag``: recorded and compared by replay like every output."""

    tag: str
    values: dict[str, Any]


@dataclass(frozen=True, slots=True)
class Picture:
    """An image a mission made (a mosaic, a map), as PNG bytes: recorded on
    ``/mission/pictures`` with ``tag`` as its frame id (the output holds its digest)."""

    tag: str
    png: bytes


Output = (
    Command
    | Event
    | Shapes
    | Plan
    | Recognition
    | Viewpoints
    | DiagonalView
    | ModelBuilt
    | Outcome
    | Result
    | Picture
)
