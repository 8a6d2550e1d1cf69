"""The vehicle's camera trigger, as ArduPilot's AP_Camera: ``DO_DIGICAM_CONTROL`` (a command or
an AUTO mission item) and ``IMAGE_START_CAPTURE`` each take one photo, which the vehicle
reports to every link as ``CAMERA_FEEDBACK`` (where it was when the shutter fired). There is
no image: a recorder on the link (``uavtool record``) takes it."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from uavtool.mavlink.dialect import mavlink as M
from uavtool.sitl.state import ACCEPTED, Result

if TYPE_CHECKING:
    from uavtool.sitl.telemetry import Telemetry


class Shutter:
    """Photos triggered and not yet reported, and how many were taken since boot."""

    def __init__(self) -> None:
        self.pending = 0
        self.taken = 0

    def trigger(self) -> Result:
        self.pending += 1
        return ACCEPTED

    def feedback(self, telemetry: Telemetry, *, target_system: int) -> list[Any]:
        """One ``CAMERA_FEEDBACK`` per photo triggered since the last call."""
        out = []
        pos, att = telemetry.global_position_int(), telemetry.attitude()
        while self.pending:
            self.pending -= 1
            out.append(
                M.MAVLink_camera_feedback_message(
                    telemetry.start_unix_us + telemetry.ap.now_ns // 1000,
                    target_system,
                    0,
                    self.taken,
                    pos.lat,
                    pos.lon,
                    pos.alt / 1000.0,
                    pos.relative_alt / 1000.0,
                    att.roll * 57.29577951308232,
                    att.pitch * 57.29577951308232,
                    (att.yaw * 57.29577951308232) % 360.0,
                    0.0,
                    M.CAMERA_FEEDBACK_PHOTO,
                    self.taken + 1,
                )
            )
            self.taken += 1
        return out
