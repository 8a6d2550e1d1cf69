"""Setting vehicle parameters (``uavtool fly --param NAME=VALUE``) with the MAVLink
parameter protocol: PARAM_SET, confirmed by the PARAM_VALUE echo."""

from __future__ import annotations

import struct

from uavtool.autopilot import Autopilot
from uavtool.checks import Range, coerce
from uavtool.errors import ParamError
from uavtool.link import VehicleLink
from uavtool.mavlink.dialect import mavlink as M
from uavtool.runner.preflight import read_param

_TRIES = 3
_WAIT_S = 1.0
_NAME_LEN = 16  # PARAM_SET.param_id
_FLOAT32 = Range(-3.4028234663852886e38, 3.4028234663852886e38)


def parse_param(text: str) -> tuple[str, float]:
    """``NAME=VALUE`` → (NAME upper-cased, VALUE); the value must fit PARAM_SET's float32.

    Whether the value is in the parameter's range is the vehicle's call (see
    :func:`set_vehicle_params`).
    """
    name, sep, value = text.partition("=")
    name = name.strip().upper()
    if not sep or not name:
        raise ParamError(
            f"--param {text!r}: expected NAME=VALUE, e.g. WPNAV_SPEED=800 (ArduPilot) or "
            "MPC_XY_CRUISE=8 (PX4)"
        )
    if len(name) > _NAME_LEN or not name.isascii():
        raise ParamError(f"--param {name!r}: a parameter name is at most 16 ASCII characters")
    number: float = coerce(value, float, name=f"--param {name}", bounds=_FLOAT32, error=ParamError)
    return name, number


def set_vehicle_params(
    link: VehicleLink, params: tuple[tuple[str, float], ...], autopilot: Autopilot
) -> None:
    """Set each parameter and wait for the vehicle to echo it; ParamError if it never does,
    or if it echoes another value (it refused this one and kept its own). On an autopilot
    that wants each parameter's own type (PX4), the parameter is read first."""
    for name, value in params:
        param_type = M.MAV_PARAM_TYPE_REAL32
        if autopilot.param_types_matter:
            current = read_param(link, name, None)
            if current is None:
                raise ParamError(f"--param {name}: the vehicle has no such parameter")
            param_type = int(current.param_type)
        for _ in range(_TRIES):
            link.send(
                M.MAVLink_param_set_message(
                    link.target_system,
                    link.target_component,
                    name.encode(),
                    autopilot.param_encoded(value, param_type),
                    param_type,
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
        kept = autopilot.param_value(echoed[-1])
        if kept != _as_float32(value):
            raise ParamError(f"--param {name}={value:g}: the vehicle refused it and kept {kept:g}")


def _as_float32(value: float) -> float:
    """``value`` as PARAM_SET carries it."""
    (out,) = struct.unpack("<f", struct.pack("<f", value))
    return float(out)
