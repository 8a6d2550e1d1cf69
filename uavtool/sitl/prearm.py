"""ArduCopter's refusals to arm while it boots: its gyros settle, then its EKF needs a
position (ArduCopter's SITL takes ~20 s of sim time; the built-in vehicle a few seconds)."""

from __future__ import annotations

_NS = 1_000_000_000
GYROS_SHARE = 0.4
"""The first part of the settling time the gyros are still inconsistent."""
SETTLED_TEXT = "EKF3 IMU0 is using GPS"


def boot_failure(now_ns: int, settle_s: float) -> str | None:
    """Why arming is refused ``now_ns`` after boot (ArduCopter's words, without "Arm: "),
    None once the vehicle has settled."""
    if now_ns >= settle_s * _NS:
        return None
    if now_ns < GYROS_SHARE * settle_s * _NS:
        return "Gyros inconsistent"
    return "Need Position Estimate"
