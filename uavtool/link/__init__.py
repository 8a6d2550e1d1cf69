"""The MAVLink client adapter: connection strings to transports, and the ground-station side
of a link to any ArduPilot-compatible vehicle."""

from uavtool.link.client import STREAMS, Clock, VehicleLink, VehicleState
from uavtool.link.transport import Transport, open_transport

__all__ = ["STREAMS", "Clock", "Transport", "VehicleLink", "VehicleState", "open_transport"]
