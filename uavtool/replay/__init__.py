"""Deterministic replay of recorded missions (``uavtool replay``): the recorded observations
through a fresh mission, every output compared with the recording; re-analysis with other
parameters; golden recordings as regression tests."""

from uavtool.replay.frames import FrameChange, reanalyse_frames
from uavtool.replay.load import RecordedFlight, RecordedOutput, ReplayInputError, load_flight
from uavtool.replay.replay import Difference, Divergence, ReplayResult, replay

__all__ = [
    "Difference",
    "Divergence",
    "FrameChange",
    "RecordedFlight",
    "RecordedOutput",
    "ReplayInputError",
    "ReplayResult",
    "load_flight",
    "reanalyse_frames",
    "replay",
]
