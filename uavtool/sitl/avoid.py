"""Stopping at the fence under velocity control, as ArduCopter's AC_Avoid does in GUIDED with
AVOID_ENABLE's "stop at fence" bit (on by default): a velocity stream that would carry the
vehicle out of the circle fence or over its altitude fence is cut to the speed from which the
vehicle can still stop at the fence less FENCE_MARGIN, braking at no more than 1 m/s².
Horizontally it slides along the circle (AVOID_BEHAVE 0, Copter's default) or stops
(AVOID_BEHAVE 1). Once a fence is breached this does nothing: the breach's action flies.
"""

from __future__ import annotations

import math

from uavtool.sitl.fence import Fence, FenceType
from uavtool.sitl.params import ParamStore
from uavtool.sitl.shaping import sqrt_controller, stopping_distance

ACCEL_MAX_MSS = 1.0
"""The braking AC_Avoid allows itself (AC_AVOID_ACCEL_CMSS_MAX)."""
STOP_AT_FENCE = 1
"""AVOID_ENABLE's bit for the fence."""
_SLIDE = 0


def adjust_velocity(
    vel_ned_ms: tuple[float, float, float],
    pos_ned_m: list[float],
    *,
    fence: Fence,
    params: ParamStore,
    pos_p: tuple[float, float],
    accel_mss: tuple[float, float],
) -> tuple[float, float, float]:
    """``vel_ned_ms`` as the fence lets the vehicle at ``pos_ned_m`` fly it. ``pos_p`` and
    ``accel_mss``: the position controller's horizontal and vertical gains (1/s) and
    accelerations, of which AC_Avoid brakes with at most :data:`ACCEL_MAX_MSS`."""
    if not int(params["AVOID_ENABLE"]) & STOP_AT_FENCE:
        return vel_ned_ms
    types = fence.types
    vn, ve, vd = vel_ned_ms
    if types & FenceType.CIRCLE and not fence.breaches & FenceType.CIRCLE:
        vn, ve = _circle(
            vn,
            ve,
            pos_ned_m,
            radius_m=params["FENCE_RADIUS"],
            margin_m=params["FENCE_MARGIN"],
            slide=int(params["AVOID_BEHAVE"]) == _SLIDE,
            p=pos_p[0],
            accel=min(accel_mss[0], ACCEL_MAX_MSS),
        )
    if types & FenceType.ALT_MAX and not fence.breaches & FenceType.ALT_MAX and vd < 0.0:
        room_m = params["FENCE_ALT_MAX"] - params["FENCE_MARGIN"] + pos_ned_m[2]
        climb = max(sqrt_controller(room_m, pos_p[1], min(accel_mss[1], ACCEL_MAX_MSS)), 0.0)
        vd = max(vd, -climb)
    return vn, ve, vd


def _circle(
    vn: float,
    ve: float,
    pos_ned_m: list[float],
    *,
    radius_m: float,
    margin_m: float,
    slide: bool,
    p: float,
    accel: float,
) -> tuple[float, float]:
    speed = math.hypot(vn, ve)
    if speed == 0.0 or margin_m > radius_m:
        return vn, ve
    n, e = pos_ned_m[0], pos_ned_m[1]
    from_home = math.hypot(n, e)
    if from_home > radius_m:
        return vn, ve
    inner = radius_m - margin_m
    reach = stopping_distance(speed, p, accel)
    if slide:
        # where the vehicle would stop; if past the inner circle, head for the inner circle's
        # point on that side instead, no faster than it can stop there
        sn, se = n + vn / speed * reach, e + ve / speed * reach
        stop_from_home = math.hypot(sn, se)
        if stop_from_home <= inner:
            return vn, ve
        tn, te = sn * inner / stop_from_home - n, se * inner / stop_from_home - e
        to_target = math.hypot(tn, te)
        if to_target <= 0.0:
            return 0.0, 0.0
        allowed = min(speed, max(sqrt_controller(to_target, p, accel), 0.0))
        return tn * allowed / to_target, te * allowed / to_target
    # stop: no further out once at the inner circle; slower as the vehicle nears it
    if from_home >= inner:
        ahead = reach + 2.0 + margin_m
        if math.hypot(n + vn / speed * ahead, e + ve / speed * ahead) >= from_home:
            return 0.0, 0.0
        return vn, ve
    to_edge = _distance_to_circle(n, e, vn / speed, ve / speed, inner)
    if to_edge is None or to_edge > reach + 2.0 + margin_m:
        return vn, ve
    allowed = max(sqrt_controller(to_edge, p, accel), 0.0)
    return (vn * allowed / speed, ve * allowed / speed) if allowed < speed else (vn, ve)


def _distance_to_circle(n: float, e: float, dn: float, de: float, radius: float) -> float | None:
    """How far along the unit direction (dn, de) from (n, e), inside a circle of ``radius``
    about home, its edge lies."""
    b = n * dn + e * de
    c = n * n + e * e - radius * radius
    disc = b * b - c
    if disc < 0.0:
        return None
    return -b + math.sqrt(disc)
