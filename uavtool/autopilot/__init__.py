"""What differs between autopilots, behind one interface: their flight modes, how each
mission command goes on the wire, their parameter names in every hint, and where their
refusal reasons come from. The mission speaks one vocabulary (``GUIDED``: the ground station
steers; ``RTL``; ``LAND``; see :class:`uavtool.mission.SetMode`) and never asks which
autopilot flies it; :func:`for_vehicle` picks the adapter from the vehicle's HEARTBEAT.
"""

from __future__ import annotations

from uavtool.autopilot.ardupilot import ArduPilot, GenericMAVLink
from uavtool.autopilot.base import (
    COMMAND_NAMES,
    RESULT_NAMES,
    Autopilot,
    Fence,
    ParamReader,
    Sent,
)
from uavtool.autopilot.px4 import PX4
from uavtool.mavlink.dialect import mavlink as M


def for_vehicle(heartbeat: object) -> Autopilot:
    """The adapter for the autopilot that sent ``heartbeat`` (its ``autopilot`` field): PX4,
    ArduPilot (and the built-in vehicle, which follows it), else ArduPilot's commands with
    no parameter names in the hints."""
    kind = getattr(heartbeat, "autopilot", None)
    if kind == M.MAV_AUTOPILOT_PX4:
        return PX4()
    if kind == M.MAV_AUTOPILOT_ARDUPILOTMEGA:
        return ArduPilot()
    return GenericMAVLink()


__all__ = [
    "COMMAND_NAMES",
    "PX4",
    "RESULT_NAMES",
    "ArduPilot",
    "Autopilot",
    "Fence",
    "GenericMAVLink",
    "ParamReader",
    "Sent",
    "for_vehicle",
]
