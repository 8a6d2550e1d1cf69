"""The one MAVLink dialect uavtool speaks: MAVLink 2, ArduPilot's ``ardupilotmega`` (with
common.xml's events messages, :mod:`uavtool.mavlink.events`)."""

from __future__ import annotations

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from uavtool.mavlink.events import register

register(mavlink)  # common.xml's EVENT messages, which pymavlink's bundled XML lacks

DIALECT = "ardupilotmega"

# ArduCopter flight modes (custom_mode numbers in HEARTBEAT).
COPTER_MODES: dict[str, int] = {
    "STABILIZE": 0,
    "ACRO": 1,
    "ALT_HOLD": 2,
    "AUTO": 3,
    "GUIDED": 4,
    "LOITER": 5,
    "RTL": 6,
    "CIRCLE": 7,
    "LAND": 9,
    "POSHOLD": 16,
    "BRAKE": 17,
    "SMART_RTL": 21,
}
COPTER_MODE_NAMES: dict[int, str] = {number: name for name, number in COPTER_MODES.items()}

__all__ = ["COPTER_MODES", "COPTER_MODE_NAMES", "DIALECT", "mavlink"]
