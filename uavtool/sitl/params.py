"""The vehicle's parameters: ArduCopter names, defaults, MAVLink types, and parameter files.

Values are stored the way they travel: REAL32 parameters are rounded to float32, integer
parameters are whole numbers, so a PARAM_SET echoes exactly what a later PARAM_REQUEST_READ
returns. A value outside the parameter's ArduCopter range (or not finite) is refused whole:
ArduPilot's parameter protocol answers such a PARAM_SET with the value it kept.
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

_FLOAT32_MAX = 3.4028234663852886e38
_INT_RANGES = {_INT8: (-128, 127), _INT16: (-32768, 32767), _INT32: (-(2**31), 2**31 - 1)}


@dataclass(frozen=True, slots=True)
class ParamSpec:
    """One parameter: ArduCopter's name, default, MAVLink type and documented ``@Range``."""

    name: str
    default: float
    mav_type: int
    low: float
    high: float
    doc: str


_I32_MAX = 2**31 - 1
P = ParamSpec
# Units follow ArduPilot: cm, cm/s, cm/s², centidegrees where ArduCopter uses them. Ranges are
# ArduCopter's @Range (or its @Values' span); the SIM_ ones keep the simulation finite and
# its telemetry inside its fields (SYS_STATUS carries the voltage as uint16 millivolts).
PARAM_SPECS: tuple[ParamSpec, ...] = (
    P("SYSID_THISMAV", 1, _INT16, 1, 255, "MAVLink system id of this vehicle"),
    P("SYSID_MYGCS", 255, _INT16, 1, 255, "system id of the ground station"),
    P("FS_GCS_ENABLE", 0, _INT8, 0, 7, "GCS failsafe: 0 off, 1 RTL, 5 LAND"),
    P("FS_GCS_TIMEOUT", 5.0, _REAL32, 2, 120, "GCS heartbeat timeout, s"),
    P("ARMING_CHECK", 1, _INT32, 0, _I32_MAX, "pre-arm checks bitmask (1 = all, 0 = none)"),
    P("DISARM_DELAY", 10, _INT8, 0, 127, "auto-disarm delay on the ground, s (0 off)"),
    P("RTL_ALT", 1500, _INT32, 30, 300000, "RTL return altitude, cm above home"),
    P("RTL_SPEED", 0, _INT16, 0, 2000, "RTL horizontal speed, cm/s (0 = WPNAV_SPEED)"),
    P("RTL_LOIT_TIME", 5000, _INT32, 0, 60000, "RTL loiter time above home before landing, ms"),
    P("LAND_SPEED", 50, _INT16, 30, 200, "final landing descent rate, cm/s"),
    P("LAND_SPEED_HIGH", 0, _INT16, 0, 2500, "descent above 10 m, cm/s (0 = WPNAV_SPEED_DN)"),
    P("WPNAV_SPEED", 1000, _REAL32, 10, 2000, "horizontal waypoint speed, cm/s"),
    P("WPNAV_SPEED_UP", 250, _REAL32, 10, 1000, "climb rate, cm/s"),
    P("WPNAV_SPEED_DN", 150, _REAL32, 10, 500, "descent rate, cm/s"),
    P("WPNAV_ACCEL", 250, _REAL32, 50, 500, "horizontal acceleration, cm/s²"),
    P("WPNAV_ACCEL_Z", 100, _REAL32, 50, 500, "vertical acceleration, cm/s²"),
    P("WPNAV_RADIUS", 200, _REAL32, 5, 1000, "waypoint reached radius, cm"),
    P("WPNAV_JERK", 1.0, _REAL32, 1, 20, "jerk along a route (AUTO, RTL), m/s³"),
    P("PSC_JERK_XY", 5.0, _REAL32, 1, 20, "horizontal jerk to a position target, m/s³"),
    P("PSC_JERK_Z", 5.0, _REAL32, 5, 50, "vertical jerk, m/s³"),
    P("PILOT_SPEED_UP", 250, _INT16, 50, 500, "maximum pilot climb rate, cm/s"),
    P("PILOT_SPEED_DN", 0, _INT16, 0, 500, "maximum pilot descent, cm/s (0 = PILOT_SPEED_UP)"),
    P("ATC_SLEW_YAW", 6000, _REAL32, 500, 18000, "maximum yaw slew rate, cdeg/s"),
    P("ANGLE_MAX", 3000, _INT16, 1000, 8000, "maximum lean angle, cdeg"),
    # The controllers' gains and shaping (ArduCopter 4.5's names; 4.8 calls the PSC_ ones
    # PSC_NE_POS_P, PSC_NE_VEL_*, PSC_D_POS_P, PSC_D_VEL_P and the ATC_ACCEL_ ones ATC_ACC_*)
    P("PSC_POSXY_P", 1.0, _REAL32, 0.5, 2.0, "horizontal position gain, 1/s"),
    P("PSC_VELXY_P", 2.0, _REAL32, 0.1, 6.0, "horizontal velocity gain, 1/s"),
    P("PSC_VELXY_I", 1.0, _REAL32, 0.02, 1.0, "horizontal velocity integral gain, 1/s²"),
    P("PSC_VELXY_IMAX", 1000.0, _REAL32, 0, 4500, "horizontal velocity integral limit, cm/s²"),
    P("PSC_POSZ_P", 1.0, _REAL32, 1.0, 3.0, "vertical position gain, 1/s"),
    P("PSC_VELZ_P", 5.0, _REAL32, 1.0, 8.0, "vertical velocity gain, 1/s"),
    P("ATC_INPUT_TC", 0.15, _REAL32, 0.0, 1.0, "attitude input time constant, s"),
    P("ATC_ACCEL_R_MAX", 110000.0, _REAL32, 0, 180000, "roll acceleration limit, cdeg/s²"),
    P("ATC_ACCEL_P_MAX", 110000.0, _REAL32, 0, 180000, "pitch acceleration limit, cdeg/s²"),
    P("ATC_ACCEL_Y_MAX", 27000.0, _REAL32, 0, 72000, "yaw acceleration limit, cdeg/s²"),
    P("MOT_SPOOL_TIME", 0.5, _REAL32, 0.05, 2.0, "motor spool-up time, s"),
    P("TKOFF_SLEW_TIME", 2.0, _REAL32, 0.25, 5.0, "take-off throttle ramp, idle to full, s"),
    P("FENCE_ENABLE", 0, _INT8, 0, 1, "geofence on (1) or off (0)"),
    P("FENCE_ALT_MAX", 100.0, _REAL32, 10, 1000, "geofence maximum altitude above home, m"),
    P("FENCE_RADIUS", 300.0, _REAL32, 30, 10000, "geofence radius around home, m"),
    P("BATT_CAPACITY", 10000, _INT32, 0, _I32_MAX, "battery capacity, mAh (~19 min hover)"),
    P("BATT_LOW_VOLT", 10.5, _REAL32, 0, 60, "low-battery voltage, V"),
    P("BATT_FS_LOW_ACT", 2, _INT8, 0, 4, "low-battery action: 0 none, 1 LAND, 2-4 RTL"),
    P("SIM_SPEEDUP", 1.0, _REAL32, 0.01, 1e9, "simulation speed-up over wall time"),
    P("SIM_WIND_SPD", 0.0, _REAL32, 0, 50, "wind speed, m/s"),
    P("SIM_WIND_DIR", 0.0, _REAL32, 0, 360, "wind direction it blows from, deg"),
    P("SIM_WIND_TURB", 0.0, _REAL32, 0, 20, "wind turbulence, m/s (seeded)"),
    P("SIM_WIND_DIR_Z", 0.0, _REAL32, -90, 90, "wind's angle above the horizontal, deg"),
    P("SIM_WIND_TC", 5.0, _REAL32, 0, 600, "time constant of wind changes, s"),
    P("SIM_WIND_T", 0, _INT8, 0, 2, "wind with height: 0 square root, 1 none, 2 linear"),
    P("SIM_WIND_T_ALT", 60.0, _REAL32, 0, 10000, "height of full wind speed (SIM_WIND_T), m"),
    P("SIM_WIND_T_COEF", 0.01, _REAL32, -1, 1, "linear wind change per m (SIM_WIND_T 2)"),
    P("SIM_GPS_NOISE", 0.0, _REAL32, 0, 100, "GPS position noise, m (seeded)"),
    P("SIM_BARO_RND", 0.0, _REAL32, 0, 100, "barometer altitude noise, m (seeded)"),
    P("SIM_BATT_VOLTAGE", 12.6, _REAL32, 0, 60, "full battery voltage, V (3S)"),
    P("SIM_RATE_HZ", 50, _INT16, 10, 1000, "physics steps per simulated second (read at start)"),
    P("MNT1_TYPE", 0, _INT8, 0, 12, "mount type (0 none, 1 servo); read at boot only"),
    P("WP_YAW_BEHAVIOR", 2, _INT8, 0, 3, "nose while flying: 0 hold, 1/2 face target, 3 course"),
    P("MNT1_PITCH_MIN", -90, _INT16, -90, 90, "gimbal minimum pitch, deg"),
    P("MNT1_PITCH_MAX", 0, _INT16, -90, 90, "gimbal maximum pitch, deg"),
    P("MNT1_YAW_MIN", -180, _INT16, -180, 180, "gimbal minimum yaw, deg"),
    P("MNT1_YAW_MAX", 180, _INT16, -180, 180, "gimbal maximum yaw, deg"),
    P("FENCE_TYPE", 7, _INT8, 0, 15, "fence types: 1 max altitude, 2 circle, 4 polygon, 8 min alt"),
    P("FENCE_ACTION", 1, _INT8, 0, 5, "on a breach: 0 report, 1 RTL or LAND, 2 LAND, 3-5 RTL/LAND"),
    P("FENCE_MARGIN", 2.0, _REAL32, 1, 10, "distance inside the fence RTL keeps to, m"),
    P("AVOID_ENABLE", 3, _INT8, 0, 7, "avoidance: 1 stop at the fence (+2 proximity, +4 beacons)"),
    P("AVOID_BEHAVE", 0, _INT8, 0, 1, "at the fence under velocity control: 0 slide, 1 stop"),
    # What each servo output drives (ArduPilot's SERVOn_FUNCTION: 6 mount yaw, 7 mount pitch,
    # 8 mount roll …). Kept so that an ArduCopter parameter file (the mount.parm of
    # docs/vehicles.md) loads as it is; the built-in vehicle's mount moves without them.
    *(
        P(f"SERVO{n}_FUNCTION", 0, _INT16, -1, 188, f"what servo output {n} drives")
        for n in range(1, 17)
    ),
)

_SPECS_BY_NAME = {spec.name: spec for spec in PARAM_SPECS}


def highest(name: str) -> float:
    """The top of a parameter's documented range (ArduCopter's @Range)."""
    return _SPECS_BY_NAME[name].high


def coerce(mav_type: int, value: float) -> float:
    """``value`` as the parameter type stores it (float32 rounding, integer clamping)."""
    if mav_type == _REAL32:
        if abs(value) > _FLOAT32_MAX:  # struct refuses to round these
            return math.copysign(math.inf, value)
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
        """Set ``name`` and return the stored value; raises ParamError (naming the range) for
        an unknown name or a value outside ArduCopter's range, leaving the table unchanged."""
        stored = check(name, value)
        self._values[name] = stored
        return stored


def check(name: str, value: float) -> float:
    """``value`` as parameter ``name`` would store it; ParamError if unknown or out of range."""
    spec = _SPECS_BY_NAME.get(name)
    if spec is None:
        raise ParamError(f"unknown parameter {name!r}")
    if not math.isfinite(value):
        raise ParamError(f"{name}: value must be finite, got {value}")
    if spec.mav_type == _REAL32:
        inside = coerce(_REAL32, spec.low) <= coerce(_REAL32, value) <= coerce(_REAL32, spec.high)
    else:
        inside = spec.low <= round(value) <= spec.high
    if not inside:
        raise ParamError(f"{name}: {value:g} out of range {spec.low:g}..{spec.high:g}")
    return coerce(spec.mav_type, value)


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
        try:
            check(name, values[name])
        except ParamError as exc:
            raise ParamError(f"{path}:{lineno}: {exc}") from None
    return values
