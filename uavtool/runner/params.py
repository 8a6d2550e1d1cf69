"""Setting vehicle parameters (``uavtool fly --param NAME=VALUE``) with the MAVLink
parameter protocol: PARAM_SET, confirmed by the PARAM_VALUE echo."""

from __future__ import annotations

from uavtool.errors import ParamError
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M

_TRIES = 3
_WAIT_S = 1.0


def parse_param(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise ParamError(f"--param {text!r}: expected NAME=VALUE, e.g. WPNAV_SPEED=800")
    try:
        return name.strip().upper(), float(value)
    except ValueError:
        raise ParamError(f"--param {text!r}: {value!r} is not a number") from None


def set_vehicle_params(link: VehicleLink, params: tuple[tuple[str, float], ...]) -> None:
    """Set each parameter and wait for the vehicle to echo it; ParamError if it never does."""
    for name, value in params:
        for _ in range(_TRIES):
            link.send(
                M.MAVLink_param_set_message(
                    link.target_system,
                    link.target_component,
                    name.encode(),
                    value,
                    M.MAV_PARAM_TYPE_REAL32,
                )
            )
            deadline = link.clock() + _WAIT_S
            while link.clock() < deadline:
                echoed = [
                    m
                    for m in link.poll(0.05)
                    if m.get_type() == "PARAM_VALUE" and m.param_id == name
                ]
                if echoed:
                    break
            else:
                continue
            break
        else:
            raise ParamError(f"--param {name}: the vehicle did not confirm it (unknown parameter?)")
