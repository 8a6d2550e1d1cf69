"""Missions: pure state machines from observations to outputs, with their parameters. No
clock, socket or unseeded random inside; the runner (``uavtool.runner``) connects one to a
vehicle and a camera, and replay to a recording.

:class:`FlightMission` is the base every mission builds on (the public API is
:mod:`uavtool.api`); :class:`SearchMission` is the built-in search-and-analyze mission
(paper section V)."""

from uavtool.mission.base import FlightMission, MissionEnd, MissionInputs, Wait
from uavtool.mission.errors import MissionInputError, MissionStateError
from uavtool.mission.mission import SearchMission
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
    Picture,
    Plan,
    PointOfInterest,
    Recognition,
    Result,
    SetGimbal,
    SetMode,
    Shapes,
    Status,
    Takeoff,
    TakePhoto,
    Viewpoints,
)
from uavtool.mission.params import FlightParams, MissionParams, Params

__all__ = [
    "Arm",
    "Command",
    "CommandResult",
    "DiagonalView",
    "Event",
    "FlightMission",
    "FlightParams",
    "GoTo",
    "Level",
    "LinkLost",
    "LinkRestored",
    "MissionEnd",
    "MissionInputError",
    "MissionInputs",
    "MissionParams",
    "MissionStateError",
    "ModelBuilt",
    "Observation",
    "Outcome",
    "Output",
    "Params",
    "Photo",
    "Picture",
    "Plan",
    "PointOfInterest",
    "Recognition",
    "Result",
    "SearchMission",
    "SetGimbal",
    "SetMode",
    "Shapes",
    "Status",
    "TakePhoto",
    "Takeoff",
    "Telemetry",
    "Viewpoints",
    "Wait",
]
