"""The search-and-analyze mission (paper section V): a pure state machine from observations
to outputs, with its parameters. No clock, socket or unseeded random inside; the runner
(``uavtool.runner``) connects it to a vehicle and a camera, and replay to a recording."""

from uavtool.mission.errors import MissionInputError, MissionStateError
from uavtool.mission.mission import Mission
from uavtool.mission.observations import (
    CommandResult,
    LinkLost,
    LinkRestored,
    Observation,
    Photo,
    Telemetry,
)
from uavtool.mission.outputs import (
    Arm,
    Command,
    DiagonalView,
    Event,
    GoTo,
    Level,
    ModelBuilt,
    Outcome,
    Output,
    Plan,
    PointOfInterest,
    Recognition,
    SetGimbal,
    SetMode,
    Shapes,
    Status,
    Takeoff,
    TakePhoto,
    Viewpoints,
)
from uavtool.mission.params import MissionParams, Params

__all__ = [
    "Arm",
    "Command",
    "CommandResult",
    "DiagonalView",
    "Event",
    "GoTo",
    "Level",
    "LinkLost",
    "LinkRestored",
    "Mission",
    "MissionInputError",
    "MissionParams",
    "MissionStateError",
    "ModelBuilt",
    "Observation",
    "Outcome",
    "Output",
    "Params",
    "Photo",
    "Plan",
    "PointOfInterest",
    "Recognition",
    "SetGimbal",
    "SetMode",
    "Shapes",
    "Status",
    "TakePhoto",
    "Takeoff",
    "Telemetry",
    "Viewpoints",
]
