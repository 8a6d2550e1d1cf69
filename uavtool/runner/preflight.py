"""Checks on the ground, before arming: what the mission needs of the vehicle and the camera.

The vehicle is asked what it has (GIMBAL_MANAGER_INFORMATION, and the autopilot's mount
parameters) so that a missing mount stops the run before take-off with the fix in its own
parameter names, not at 45 m with a refused gimbal command; and its geofence, so that a fence
below the second overview or inside the search square stops it too, not at the fence with an
RTL. Every wait is on
the link's clock (vehicle time in lockstep).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from uavtool.autopilot import Autopilot, ParamReader
from uavtool.camera import CameraPose
from uavtool.errors import InputError
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M
from uavtool.mission.base import Envelope
from uavtool.runner.camera import CameraSource

ANSWER_S = 3.0
"""How long the vehicle has to answer each question."""
RETRY_S = 0.5
"""How often an unanswered question is asked again."""
UNHEARD_S = 15.0
"""How long a command that the vehicle never acknowledges is asked again: on a lossy link
silence is not an answer, so :data:`ANSWER_S` only counts once the vehicle has shown it heard."""


class PreflightError(InputError):
    """The vehicle or the camera lacks what the mission needs; raised before arming."""


def check_home(link: VehicleLink) -> None:
    if link.state.home is None:
        raise PreflightError(f"{link.name}: the vehicle has no home position; wait for GPS")


def check_camera(camera: CameraSource) -> None:
    """One frame from the camera, or PreflightError."""
    try:
        camera.capture(CameraPose((0.0, 0.0, 0.0), 0.0, -90.0))
    except Exception as exc:  # any camera failure stops the run on the ground
        raise PreflightError(f"camera: no frame before take-off: {exc}") from None


def check_gimbal(
    link: VehicleLink,
    autopilot: Autopilot,
    *,
    need_pitch_deg: tuple[float, float] = (-90.0, 0.0),
    on_wait: Callable[[], None] | None = None,
) -> tuple[float, float]:
    """The gimbal's pitch range (degrees) if it can point at each of ``need_pitch_deg``:
    a gimbal manager's (GIMBAL_MANAGER_INFORMATION, protocol v2), else the range of a mount
    the autopilot drives with gimbal protocol v1 only; PreflightError naming the fix
    otherwise."""
    info = _ask(
        link,
        lambda: link.command_long(
            M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_GIMBAL_MANAGER_INFORMATION
        ),
        "GIMBAL_MANAGER_INFORMATION",
        on_wait,
        acked_by=M.MAV_CMD_REQUEST_MESSAGE,
    )
    if info is not None:
        low, high = math.degrees(info.pitch_min), math.degrees(info.pitch_max)
    elif (v1 := autopilot.mount_v1(param_reader(link, autopilot, on_wait))) is not None:
        low, high = v1
    else:
        fix = autopilot.gimbal_fix(param_reader(link, autopilot, on_wait))
        raise PreflightError(f"the vehicle has no gimbal: {fix}; or fly with --no-gimbal")
    missing = [p for p in need_pitch_deg if not low - 0.5 <= p <= high + 0.5]
    if missing:
        raise PreflightError(
            f"the gimbal pitches {low:g}..{high:g}° but the mission needs "
            f"{', '.join(f'{p:g}°' for p in missing)}: {autopilot.pitch_fix()}"
        )
    return low, high


def check_fence(
    link: VehicleLink,
    autopilot: Autopilot,
    envelope: Envelope,
    *,
    on_wait: Callable[[], None] | None = None,
) -> None:
    """PreflightError when the vehicle's geofence is on and keeps it from where the mission
    must fly (``envelope``): an altitude limit below the highest it climbs, or a horizontal
    one closer than the farthest it goes. The vehicle would refuse the move or breach the
    fence and return home mid-mission. A vehicle whose parameters do not answer, or a mission
    that does not say where it flies, passes. Each fence parameter is asked for
    :data:`UNHEARD_S`: on a lossy link a few lost answers in a row would otherwise pass a
    fence that stops the mission mid-flight."""
    if envelope.altitude_m is None and envelope.distance_m is None:
        return
    fence = autopilot.fence(param_reader(link, autopilot, on_wait, within_s=UNHEARD_S))
    if fence is None:
        return
    up, out = envelope.altitude_m, envelope.distance_m
    if up is not None and fence.alt_max_m is not None and fence.alt_max_m < up:
        name = fence.alt_param
        lower = f", or lower {envelope.shrink_up}" if envelope.shrink_up else ""
        raise PreflightError(
            f"the altitude fence is on at {name}={fence.alt_max_m:g} m but the mission climbs "
            f"to {up:.1f} m above home{' ' if envelope.why_up else ''}{envelope.why_up}: "
            f"set {name}={math.ceil(up) + 5}{lower}"
        )
    if out is not None and fence.radius_m is not None and fence.radius_m < out:
        name = fence.radius_param
        lower = f", or lower {envelope.shrink_out}" if envelope.shrink_out else ""
        what = envelope.why_out or "the mission flies up to"
        raise PreflightError(
            f"the fence is on at {name}={fence.radius_m:g} m from home but {what} "
            f"{out:.1f} m from home: set {name} above {math.ceil(out)}{lower}"
        )


def param_reader(
    link: VehicleLink,
    autopilot: Autopilot,
    on_wait: Callable[[], None] | None,
    *,
    within_s: float = ANSWER_S,
) -> ParamReader:
    def read(name: str) -> float | None:
        msg = read_param(link, name, on_wait, within_s=within_s)
        return None if msg is None else autopilot.param_value(msg)

    return read


def read_param(
    link: VehicleLink,
    name: str,
    on_wait: Callable[[], None] | None,
    *,
    within_s: float = ANSWER_S,
) -> Any:
    """The vehicle's PARAM_VALUE for ``name``, or None if it does not answer ``within_s``
    (PARAM_REQUEST_READ has no acknowledgement: a vehicle without the parameter and a link
    that lost every question look alike)."""
    return _ask(
        link,
        lambda: link.send(
            M.MAVLink_param_request_read_message(
                link.target_system, link.target_component, name.encode(), -1
            )
        ),
        "PARAM_VALUE",
        on_wait,
        lambda msg: _param_name(msg) == name,
        within_s=within_s,
    )


def _param_name(msg: Any) -> str:
    name = msg.param_id
    return (name.decode(errors="replace") if isinstance(name, bytes) else str(name)).rstrip("\0")


def _ask(
    link: VehicleLink,
    request: Callable[[], None],
    kind: str,
    on_wait: Callable[[], None] | None,
    wanted: Callable[[Any], bool] = lambda _msg: True,
    *,
    acked_by: int | None = None,
    within_s: float = ANSWER_S,
) -> Any:
    """The first ``kind`` message after ``request`` that is ``wanted`` (a parameter's value,
    not another one's), asked again every :data:`RETRY_S` (a lossy link may drop the
    question or the answer); None after ``within_s`` (:data:`ANSWER_S`).

    A request that is a command (``acked_by``, its id) waits :data:`ANSWER_S` from the first
    COMMAND_ACK for it: a vehicle that has heard the question and sends nothing has nothing
    to send. One that acknowledges none is asked for :data:`UNHEARD_S` (dozens of questions,
    more than a lossy link loses in a row) and is then taken not to know the command."""
    deadline = link.clock() + (within_s if acked_by is None else UNHEARD_S)
    asked = -math.inf
    while link.clock() < deadline:
        if link.clock() - asked >= RETRY_S:
            request()
            asked = link.clock()
        for msg in link.poll(0.05):
            if msg.get_type() == kind and wanted(msg):
                return msg
            if acked_by is not None and msg.get_type() == "COMMAND_ACK" and msg.command == acked_by:
                deadline = min(deadline, link.clock() + ANSWER_S)
                acked_by = None  # heard: from now on the answer's own time
        if on_wait is not None:
            on_wait()
    return None
