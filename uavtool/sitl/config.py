"""The SITL vehicle's start-up configuration (what ``uavtool sitl`` options set)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from uavtool.errors import InputError
from uavtool.geo import GeoPoint
from uavtool.sitl.obstacles import Prism

DEFAULT_ENDPOINTS = ("tcpin:127.0.0.1:5760", "udpout:127.0.0.1:14550")
# ArduPilot SITL's default home: Canberra Model Aircraft Club field.
DEFAULT_HOME = (-35.363261, 149.165230, 584.0, 353.0)


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
    """The vehicle's body for collisions: a sphere of this radius around its position (0.4 m:
    a 450–500 mm quadcopter with its propellers). Used against obstacles only; the ground is
    met by the position itself, as landing gear would."""

    def __post_init__(self) -> None:
        for start_s, duration_s in self.link_outages_s:
            if start_s < 0 or duration_s <= 0:
                raise InputError(
                    f"link outage {start_s:g}:{duration_s:g}: start must be ≥ 0, duration > 0"
                )
        if not 1 <= self.sysid + self.instance <= 254:
            raise InputError(f"sysid {self.sysid} + instance {self.instance} must be in 1-254")
        if self.instance < 0:
            raise InputError(f"instance must be ≥ 0, got {self.instance}")
        if not self.speedup > 0:
            raise InputError(f"speedup must be > 0, got {self.speedup}")
        if self.signing_key is not None and len(self.signing_key) != 32:
            raise InputError("signing key must be 32 bytes (64 hex digits)")
        if self.wind_speed_ms < 0:
            raise InputError(f"wind speed must be ≥ 0, got {self.wind_speed_ms}")
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
    if not (-90 <= lat <= 90 and -180 <= lon <= 180):
        raise InputError(f"--home {text!r}: latitude/longitude out of range")
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
    return speed_ms, from_deg


def parse_outage(text: str) -> tuple[float, float]:
    """``START:DURATION`` (seconds of sim time) → a link outage window."""
    try:
        start_s, duration_s = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError(f"--link-outage {text!r}: expected START:DURATION in seconds") from None
    return start_s, duration_s
