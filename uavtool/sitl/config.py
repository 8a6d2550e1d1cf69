"""The SITL vehicle's start-up configuration (what ``uavtool sitl`` options set)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uavtool.errors import InputError, ParamError
from uavtool.geo import GeoPoint
from uavtool.sitl.args import lat_lon_ok
from uavtool.sitl.obstacles import Prism
from uavtool.sitl.params import check

DEFAULT_ENDPOINTS = ("tcpin:127.0.0.1:5760", "udpout:127.0.0.1:14550")
# ArduPilot SITL's default home: Canberra Model Aircraft Club field.
DEFAULT_HOME = (-35.363261, 149.165230, 584.0, 353.0)
ARMING_SETTLE_S = 4.0
"""The built-in vehicle's boot settling (ArduCopter's SITL takes ~20 s: a few seconds keep
tests short and still show the refusals)."""
WIND_RANGE_MS = (0.0, 50.0)  # SIM_WIND_SPD's range
HOME_ALT_RANGE_M = (-1000.0, 10000.0)
"""Home altitudes above mean sea level the vehicle accepts (the Dead Sea to above Everest)."""


@dataclass(frozen=True, slots=True)
class SitlConfig:
    """How to start a vehicle. ``speedup`` ≥ 1000 means "as fast as the CPU allows"."""

    endpoints: tuple[str, ...] = DEFAULT_ENDPOINTS
    home: GeoPoint = field(default_factory=lambda: GeoPoint(*DEFAULT_HOME[:3]))
    home_heading_deg: float = DEFAULT_HOME[3]
    speedup: float = 1.0
    sysid: int = 1
    compid: int = 1
    instance: int = 0
    wind_speed_ms: float = 0.0
    wind_dir_deg: float = 0.0
    seed: int = 0
    signing_key: bytes | None = None
    params: tuple[tuple[str, float], ...] = ()
    start_unix_us: int | None = None
    """What the vehicle's clock (SYSTEM_TIME) reads at boot; None: the wall clock at start.
    Lockstep flights fix it so that the bytes the vehicle sends depend on nothing else."""
    link_outages_s: tuple[tuple[float, float], ...] = ()
    """Fault injection: ``(start, duration)`` windows of sim time (s since start) during which
    every link is cut both ways, as if the radio failed."""
    obstacles: tuple[Prism, ...] = ()
    """What the vehicle can collide with: prisms in metres east/north of ``home`` and above it
    (``uavtool sitl --scene`` turns a scene's buildings into these). Touching one in flight
    is a crash; a NAV_TAKEOFF that would climb into one is DENIED."""
    body_radius_m: float = 0.4
    arming_settle_s: float = 0.0
    """Sim seconds after boot during which arming is refused with ArduCopter's texts ("Arm:
    Gyros inconsistent", then "Arm: Need Position Estimate"); 0: armable at once
    (``uavtool sitl`` boots with :data:`ARMING_SETTLE_S`)."""
    mount_roll_trim_deg: float = 0.0
    """The roll a stabilised servo mount keeps, reported and real; 0: a perfect gimbal
    (``uavtool sitl`` boots with :data:`SERVO_ROLL_TRIM_DEG`, as ArduCopter's servo mount)."""
    """The vehicle's body for collisions: a sphere of this radius around its position (0.4 m:
    a 450–500 mm quadcopter with its propellers). Used against obstacles only; the ground is
    met by the position itself, as landing gear would."""

    def __post_init__(self) -> None:
        for start_s, duration_s in self.link_outages_s:
            if not (0 <= start_s < math.inf and 0 < duration_s < math.inf):
                raise InputError(
                    f"link outage {start_s:g}:{duration_s:g}: start must be ≥ 0, duration > 0"
                )
        home = self.home
        if not lat_lon_ok(home.lat_deg, home.lon_deg):
            raise InputError(f"home {home.lat_deg:g},{home.lon_deg:g}: no such position")
        if not HOME_ALT_RANGE_M[0] <= home.alt_amsl_m <= HOME_ALT_RANGE_M[1]:
            low, high = HOME_ALT_RANGE_M
            raise InputError(f"home altitude {home.alt_amsl_m:g} m: not in {low:g}..{high:g} m")
        if not math.isfinite(self.home_heading_deg):
            raise InputError(f"home heading must be finite, got {self.home_heading_deg}")
        if not 1 <= self.sysid + self.instance <= 254:
            raise InputError(f"sysid {self.sysid} + instance {self.instance} must be in 1-254")
        if self.instance < 0:
            raise InputError(f"instance must be ≥ 0, got {self.instance}")
        if not self.speedup > 0:
            raise InputError(f"speedup must be > 0, got {self.speedup}")
        if self.signing_key is not None and len(self.signing_key) != 32:
            raise InputError("signing key must be 32 bytes (64 hex digits)")
        if not math.isfinite(self.wind_dir_deg):
            raise InputError(f"wind direction must be finite, got {self.wind_dir_deg}")
        # The vehicle's parameters, with ArduCopter's ranges (ParamError names the value).
        for what, name, value in (
            ("speedup", "SIM_SPEEDUP", self.speedup),
            ("wind speed", "SIM_WIND_SPD", self.wind_speed_ms),
        ):
            try:
                check(name, value)
            except ParamError as exc:
                raise ParamError(f"{what} {value:g}: {exc}") from None
        for name, value in self.params:
            check(name, value)
        if not 0.0 < self.body_radius_m < math.inf:
            raise InputError(f"body radius must be > 0 m, got {self.body_radius_m}")


def parse_home(text: str) -> tuple[GeoPoint, float]:
    """``LAT,LON,ALT,HDG`` → (home, heading). Raises InputError naming the bad part."""
    parts = text.split(",")
    if len(parts) != 4:
        raise InputError(f"--home {text!r}: expected LAT,LON,ALT,HDG")
    try:
        lat, lon, alt, hdg = (float(p) for p in parts)
    except ValueError:
        raise InputError(f"--home {text!r}: all four values must be numbers") from None
    if not lat_lon_ok(lat, lon):
        raise InputError(f"--home {text!r}: latitude/longitude out of range")
    if not HOME_ALT_RANGE_M[0] <= alt <= HOME_ALT_RANGE_M[1]:
        low, high = HOME_ALT_RANGE_M
        raise InputError(f"--home {text!r}: altitude must be {low:g}..{high:g} m")
    if not math.isfinite(hdg):
        raise InputError(f"--home {text!r}: heading must be finite")
    return GeoPoint(lat, lon, alt), hdg % 360.0


def parse_signing_key(text: str) -> bytes:
    try:
        key = bytes.fromhex(text)
    except ValueError:
        raise InputError("--signing-key: not a hex string") from None
    if len(key) != 32:
        raise InputError(f"--signing-key: need 32 bytes (64 hex digits), got {len(key)}")
    return key


def parse_wind(text: str) -> tuple[float, float]:
    """``SPEED,DIR`` (m/s, blowing from DIR degrees) → (speed, direction)."""
    try:
        speed_ms, from_deg = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--wind {text!r}: expected SPEED,DIR, e.g. 5,270") from None
    low, high = WIND_RANGE_MS
    if not low <= speed_ms <= high:
        raise InputError(f"--wind {text!r}: speed must be {low:g}..{high:g} m/s")
    if not math.isfinite(from_deg):
        raise InputError(f"--wind {text!r}: direction must be finite")
    return speed_ms, from_deg % 360.0


def parse_param(text: str) -> tuple[str, float]:
    """``NAME=VALUE`` → (name, value), checked against the parameter's range."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise ParamError(f"--param {text!r}: expected NAME=VALUE, e.g. WPNAV_SPEED=800")
    try:
        value = float(raw)
    except ValueError:
        raise ParamError(f"--param {text!r}: {raw!r} is not a number") from None
    name = name.strip().upper()
    try:
        check(name, value)
    except ParamError as exc:
        raise ParamError(f"--param {text!r}: {exc}") from None
    return name, value


def parse_duration(seconds: float | None) -> float | None:
    """``--duration``: None (run until stopped) or a finite number of seconds > 0."""
    if seconds is not None and not 0 < seconds < math.inf:
        raise InputError(f"--duration {seconds:g}: expected a number of seconds > 0")
    return seconds


def parse_outage(text: str) -> tuple[float, float]:
    """``START:DURATION`` (seconds of sim time) → a link outage window."""
    try:
        start_s, duration_s = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError(f"--link-outage {text!r}: expected START:DURATION in seconds") from None
    return start_s, duration_s
