"""Recording flights uavtool does not fly (``uavtool record``): a pilot's, a ground station's,
an AUTO mission's, the user's own code's. The link, cameras and recording writer are those of
``uavtool fly``; there is no mission, so nothing is ever commanded."""

from uavtool.recorder.config import RecordConfig, RecordSummary, Stop, VehicleSummary
from uavtool.recorder.frames import POSE_WAIT_S, Frame, FrameTaker, PoseTrack
from uavtool.recorder.session import record
from uavtool.recorder.watch import TRIGGER_MERGE_S, Event, VehicleWatch

__all__ = [
    "POSE_WAIT_S",
    "TRIGGER_MERGE_S",
    "Event",
    "Frame",
    "FrameTaker",
    "PoseTrack",
    "RecordConfig",
    "RecordSummary",
    "Stop",
    "VehicleSummary",
    "VehicleWatch",
    "record",
]
