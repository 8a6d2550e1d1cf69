"""The link remembers the gimbal angles of each status it has seen (a steady gimbal repeats
itself ten times a second): what it remembers is exactly what it would compute again, to the
sign of a zero, for every quaternion, flag and heading, NaN included."""

from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

from uavtool.link.client import VehicleLink, _gimbal_angles
from uavtool.mavlink.dialect import mavlink as M

_QS = [
    (1.0, 0.0, 0.0, 0.0),
    (1.0, -0.0, 0.0, -0.0),
    (0.707106, -0.000787, -0.707106, -0.000787),
    (0.707106, 0.0, -0.707106, 0.0),
    (float("nan"), 0.0, 0.0, 0.0),
    (0.0, 0.0, 0.0, 0.0),
]
_FLAGS = [0, M.GIMBAL_DEVICE_FLAGS_YAW_IN_VEHICLE_FRAME, M.GIMBAL_DEVICE_FLAGS_YAW_IN_EARTH_FRAME]
_HEADINGS = [0.0, -0.0, 90.0, 353.0, 359.99]


def test_remembered_angles_are_the_computed_ones() -> None:
    link = SimpleNamespace(_gimbal_seen={})
    for _ in range(2):  # the second time round, every answer comes from memory
        for q, flags, heading in itertools.product(_QS, _FLAGS, _HEADINGS):
            msg = M.MAVLink_gimbal_device_attitude_status_message(
                1, 1, 0, flags, list(q), 0.0, 0.0, 0.0, 0
            )
            remembered = VehicleLink._gimbal_angles_of(link, msg, heading)  # type: ignore[arg-type]
            computed = _gimbal_angles(msg, heading)
            assert repr(remembered) == repr(computed), (q, flags, heading)
    assert len(link._gimbal_seen) == len(_QS) * len(_FLAGS) * len(_HEADINGS)
    assert any(math.copysign(1.0, a) < 0 for a in itertools.chain(*link._gimbal_seen.values()))
