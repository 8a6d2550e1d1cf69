"""`foxglove.VehicleEncoder` writes the vehicle's pose and fix as `foxglove.encode` does, byte
for byte, whatever the last sample it encoded held."""

from __future__ import annotations

import itertools
import math

from uavtool.recording import LocationFix, Pose, PosesInFrame
from uavtool.recording.foxglove import VehicleEncoder, encode

_VALUES = (0.0, -0.0, 1.0, -2.5, 1e-300, 123456.789, 1e16, -45.0, math.inf, math.nan)
_HEADINGS = (0.0, 90.0, -90.0, 180.0, 359.9, 45.5, 450.0)
_TIMES = (1, 999_999_999, 1_000_000_000, 1_700_000_000_123_456_789, 2**63)


def test_poses_and_fixes_are_the_bytes_encode_writes() -> None:
    encoder = VehicleEncoder()
    values = itertools.cycle(_VALUES)
    for t_ns, heading in itertools.product(_TIMES, _HEADINGS):
        for _ in range(len(_VALUES)):  # each value in each place, after every other
            pos = (next(values), next(values), next(values))
            pose = PosesInFrame((Pose.from_enu_heading(pos, heading),))
            assert encoder.pose(pos, heading, t_ns) == encode(pose, t_ns)
            fix = LocationFix(*pos)
            assert encoder.fix(*pos, t_ns) == encode(fix, t_ns)
