"""The vehicle's parameters: ArduCopter names, defaults, MAVLink types, and parameter files.

Values are stored the way they travel: REAL32 parameters are rounded to float32, integer
parameters are whole numbers clamped to their type's range, so a PARAM_SET echoes exactly
what a later PARAM_REQUEST_READ returns.
"""

from __future__ import annotations

import math
import re
import struct
from dataclasses import dataclass
from pathlib import Path

from uavtool.errors import ParamError
from uavtool.mavlink.dialect import mavlink

_INT8 = mavlink.MAV_PARAM_TYPE_INT8
_INT16 = mavlink.MAV_PARAM_TYPE_INT16
_INT32 = mavlink.MAV_PARAM_TYPE_INT32
_REAL32 = mavlink.MAV_PARAM_TYPE_REAL32

_INT_RANGES = {_INT8: (-128, 127), _INT16: (-32768, 32767), _INT32: (-(2**31), 2**31 - 1)}


@dataclass(frozen=True, slots=True)
class ParamSpec:
    name: str
    default: float
    mav_type: int
    doc: str


# Units follow ArduPilot: cm, cm/s, cm/s², centidegrees where ArduCopter uses them.
PARAM_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("SYSID_THISMAV", 1, _INT16, "MAVLink system id of this vehicle"),
    ParamSpec("SYSID_MYGCS", 255, _INT16, "system id of the ground station"),
    ParamSpec("FS_GCS_ENABLE", 0, _INT8, "GCS failsafe: 0 off, 1 RTL, 5 LAND"),
    ParamSpec("FS_GCS_TIMEOUT", 5.0, _REAL32, "GCS heartbeat timeout, s"),
    ParamSpec("ARMING_CHECK", 1, _INT32, "pre-arm checks bitmask (1 = all, 0 = none)"),
    ParamSpec("DISARM_DELAY", 10, _INT8, "auto-disarm delay on the ground, s (0 off)"),
    ParamSpec("RTL_ALT", 1500, _INT32, "RTL return altitude, cm above home"),
    ParamSpec("RTL_SPEED", 0, _INT16, "RTL horizontal speed, cm/s (0 = WPNAV_SPEED)"),
    ParamSpec("RTL_LOIT_TIME", 0, _INT32, "RTL loiter time above home before landing, ms"),
    ParamSpec("LAND_SPEED", 50, _INT16, "final landing descent rate, cm/s"),
    ParamSpec(
        "LAND_SPEED_HIGH", 0, _INT16, "landing descent above 10 m, cm/s (0 = WPNAV_SPEED_DN)"
    ),
    ParamSpec("WPNAV_SPEED", 1000, _REAL32, "horizontal waypoint speed, cm/s"),
    ParamSpec("WPNAV_SPEED_UP", 250, _REAL32, "climb rate, cm/s"),
    ParamSpec("WPNAV_SPEED_DN", 150, _REAL32, "descent rate, cm/s"),
    ParamSpec("WPNAV_ACCEL", 250, _REAL32, "horizontal acceleration, cm/s²"),
    ParamSpec("WPNAV_ACCEL_Z", 100, _REAL32, "vertical acceleration, cm/s²"),
    ParamSpec("WPNAV_RADIUS", 200, _REAL32, "waypoint reached radius, cm"),
    ParamSpec("PILOT_SPEED_UP", 250, _INT16, "maximum pilot climb rate, cm/s"),
    ParamSpec("PILOT_SPEED_DN", 0, _INT16, "maximum pilot descent rate, cm/s (0 = PILOT_SPEED_UP)"),
    ParamSpec("ATC_SLEW_YAW", 6000, _REAL32, "maximum yaw slew rate, cdeg/s"),
    ParamSpec("ANGLE_MAX", 3000, _INT16, "maximum lean angle, cdeg"),
    ParamSpec("FENCE_ENABLE", 1, _INT8, "geofence on (1) or off (0)"),
    ParamSpec("FENCE_ALT_MAX", 100.0, _REAL32, "geofence maximum altitude above home, m"),
    ParamSpec("FENCE_RADIUS", 300.0, _REAL32, "geofence radius around home, m"),
    ParamSpec("BATT_CAPACITY", 5000, _INT32, "battery capacity, mAh"),
    ParamSpec("BATT_LOW_VOLT", 14.0, _REAL32, "low-battery voltage, V"),
    ParamSpec("BATT_FS_LOW_ACT", 2, _INT8, "low-battery action: 0 none, 1 LAND, 2 RTL"),
    ParamSpec("SIM_SPEEDUP", 1.0, _REAL32, "simulation speed-up over wall time"),
    ParamSpec("SIM_WIND_SPD", 0.0, _REAL32, "wind speed, m/s"),
    ParamSpec("SIM_WIND_DIR", 0.0, _REAL32, "wind direction it blows from, deg"),
    ParamSpec("SIM_WIND_TURB", 0.0, _REAL32, "wind turbulence, m/s (seeded)"),
    ParamSpec("SIM_GPS_NOISE", 0.0, _REAL32, "GPS position noise, m (seeded)"),
    ParamSpec("SIM_BARO_RND", 0.0, _REAL32, "barometer altitude noise, m (seeded)"),
    ParamSpec("SIM_BATT_VOLTAGE", 16.8, _REAL32, "full battery voltage, V"),
    ParamSpec("SIM_RATE_HZ", 50, _INT16, "physics steps per simulated second (read at start)"),
    ParamSpec("MNT1_TYPE", 1, _INT8, "mount type (1 = servo gimbal present)"),
    ParamSpec("MNT1_PITCH_MIN", -90, _INT16, "gimbal minimum pitch, deg"),
    ParamSpec("MNT1_PITCH_MAX", 0, _INT16, "gimbal maximum pitch, deg"),
    ParamSpec("MNT1_YAW_MIN", -180, _INT16, "gimbal minimum yaw, deg"),
    ParamSpec("MNT1_YAW_MAX", 180, _INT16, "gimbal maximum yaw, deg"),
)

_SPECS_BY_NAME = {spec.name: spec for spec in PARAM_SPECS}


def coerce(mav_type: int, value: float) -> float:
    """``value`` as the parameter type stores it (float32 rounding, integer clamping)."""
    if mav_type == _REAL32:
        return float(struct.unpack("<f", struct.pack("<f", value))[0])
    low, high = _INT_RANGES[mav_type]
    return float(min(max(round(value), low), high))


class ParamStore:
    """The live parameter table (name → value), in the fixed order of ``PARAM_SPECS``."""

    def __init__(self) -> None:
        self._values: dict[str, float] = {
            s.name: coerce(s.mav_type, s.default) for s in PARAM_SPECS
        }
        self._names: list[str] = [s.name for s in PARAM_SPECS]

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, name: object) -> bool:
        return name in self._values

    def __getitem__(self, name: str) -> float:
        return self._values[name]

    def names(self) -> list[str]:
        return list(self._names)

    def index(self, name: str) -> int:
        return self._names.index(name)

    def name_at(self, index: int) -> str | None:
        return self._names[index] if 0 <= index < len(self._names) else None

    def mav_type(self, name: str) -> int:
        return _SPECS_BY_NAME[name].mav_type

    def set(self, name: str, value: float) -> float:
        """Set ``name`` and return the stored value; raises ParamError for an unknown name."""
        spec = _SPECS_BY_NAME.get(name)
        if spec is None:
            raise ParamError(f"unknown parameter {name!r}")
        if not math.isfinite(value):
            raise ParamError(f"parameter {name}: value must be finite, got {value}")
        stored = coerce(spec.mav_type, value)
        self._values[name] = stored
        return stored


_LINE = re.compile(r"^\s*([A-Za-z0-9_]+)\s*[,\s]\s*([-+0-9.eE]+)\s*(?:#.*)?$")


def load_param_file(path: Path) -> dict[str, float]:
    """Read a MAVProxy/Mission Planner parameter file (``NAME VALUE`` or ``NAME,VALUE``).

    Raises ParamError naming the file and line for a malformed line or unknown name.
    """
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParamError(f"{path}: cannot read parameter file: {exc.strerror}") from None
    values: dict[str, float] = {}
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        match = _LINE.match(stripped)
        if match is None:
            raise ParamError(f"{path}:{lineno}: expected 'NAME VALUE', got {stripped!r}")
        name, raw = match.groups()
        if name not in _SPECS_BY_NAME:
            raise ParamError(f"{path}:{lineno}: unknown parameter {name!r}")
        try:
            values[name] = float(raw)
        except ValueError:
            raise ParamError(f"{path}:{lineno}: {name}: not a number: {raw!r}") from None
    return values
