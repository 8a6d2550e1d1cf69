"""The public API for writing missions: everything a mission sees, emits and calls.

A mission is a :class:`FlightMission` subclass with a parameters type and one generator,
``fly``; uavtool flies it on the built-in vehicle, ArduPilot, PX4 or a real drone, records it,
replays it bit for bit, re-flies it and sweeps its parameters, exactly as its own mission::

    from dataclasses import dataclass, field
    from uavtool.api import NADIR_DEG, FlightMission, FlightParams, Wait

    @dataclass(frozen=True, slots=True)
    class Hop:
        altitude_m: float = 20.0

    @dataclass(frozen=True, slots=True)
    class HopParams:
        hop: Hop = field(default_factory=Hop)
        flight: FlightParams = field(default_factory=FlightParams)

    class HopMission(FlightMission):
        \"\"\"Take off, take one photo straight down, land.\"\"\"

        params_type = HopParams
        params: HopParams

        def fly(self) -> Wait[str]:
            yield from self.arm_and_take_off(self.params.hop.altitude_m)
            photo = yield from self.photo("down", NADIR_DEG)
            return f"one photo, frame {photo.frame_index}"

``uavtool fly --mission my_module:HopMission --set hop.altitude_m=30`` flies it. The rules
that make replay exact: the mission reads no clock (its time is the telemetry's
``time_boot_ms``, :meth:`FlightMission.now_ms`), no socket, no file and no unseeded random
generator, and decides only on the observations it is given.
"""

from __future__ import annotations

from uavtool.camera import CameraPose, Intrinsics, pixel_ray, project
from uavtool.images import png_decode, png_encode
from uavtool.mission.airspace import Airspace, Claim
from uavtool.mission.base import (
    HORIZONTAL_DEG,
    NADIR_DEG,
    Envelope,
    FlightMission,
    MissionEnd,
    MissionInputs,
    Wait,
)
from uavtool.mission.fleet import Crew, FleetMember, FleetParams
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
    Event,
    GoTo,
    Level,
    Outcome,
    Output,
    Picture,
    Result,
    SetGimbal,
    SetMode,
    Status,
    Takeoff,
    TakePhoto,
)
from uavtool.mission.params import FlightParams
from uavtool.vision.detection import Detection, Frame

__all__ = [
    "HORIZONTAL_DEG",
    "NADIR_DEG",
    "Airspace",
    "Arm",
    "CameraPose",
    "Claim",
    "Command",
    "CommandResult",
    "Crew",
    "Detection",
    "Envelope",
    "Event",
    "FleetMember",
    "FleetParams",
    "FlightMission",
    "FlightParams",
    "Frame",
    "GoTo",
    "Intrinsics",
    "Level",
    "LinkLost",
    "LinkRestored",
    "MissionEnd",
    "MissionInputs",
    "Observation",
    "Outcome",
    "Output",
    "Photo",
    "Picture",
    "Result",
    "SetGimbal",
    "SetMode",
    "Status",
    "TakePhoto",
    "Takeoff",
    "Telemetry",
    "Wait",
    "pixel_ray",
    "png_decode",
    "png_encode",
    "project",
]
