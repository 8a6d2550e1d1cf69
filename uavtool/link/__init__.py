"""The MAVLink client adapter: connection strings to transports, and the ground-station side
of a link to any ArduPilot-compatible vehicle."""

from uavtool.link.client import STREAMS, VehicleLink, VehicleState
from uavtool.link.transport import Transport, open_transport

__all__ = ["STREAMS", "Transport", "VehicleLink", "VehicleState", "open_transport"]
