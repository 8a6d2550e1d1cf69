"""Frames and units: the one place that converts between WGS-84, local NED and local ENU.

Inside uavtool, positions are metres in a local **ENU** frame around home (x east, y north,
z up); MAVLink speaks **NED** for local positions and WGS-84 (degrees ×1e7, millimetres) for
global ones. Headings are degrees clockwise from north in [0, 360).

Global ↔ local uses ArduPilot's own flat-earth scaling (``Location::get_distance_NE`` /
``offset``): exact enough for the few hundred metres a mission spans, and identical to what
an ArduPilot vehicle computes, so offsets agree with ArduPilot's SITL to the millimetre.
Only IEEE + − × ÷ and ``math`` functions are used, so results are bit-identical everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# ArduPilot's LOCATION_SCALING_FACTOR: metres per 1e-7 degree of latitude.
_M_PER_E7 = 0.011131884502145034


@dataclass(frozen=True, slots=True)
class GeoPoint:
    """A WGS-84 position: degrees and metres above mean sea level."""

    lat_deg: float
    lon_deg: float
    alt_amsl_m: float

    @property
    def lat_e7(self) -> int:
        return round(self.lat_deg * 1e7)

    @property
    def lon_e7(self) -> int:
        return round(self.lon_deg * 1e7)


def _lon_scale(lat_deg: float) -> float:
    # ArduPilot clamps the cosine to 0.01 so the poles do not divide by zero.
    return max(math.cos(math.radians(lat_deg)), 0.01)


def enu_from_geo(home: GeoPoint, point: GeoPoint) -> tuple[float, float, float]:
    """Local ENU metres of ``point`` relative to ``home`` (up = altitude difference)."""
    d_lat_e7 = (point.lat_deg - home.lat_deg) * 1e7
    d_lon_e7 = (point.lon_deg - home.lon_deg) * 1e7
    north_m = d_lat_e7 * _M_PER_E7
    east_m = d_lon_e7 * _M_PER_E7 * _lon_scale((home.lat_deg + point.lat_deg) / 2.0)
    return (east_m, north_m, point.alt_amsl_m - home.alt_amsl_m)


def geo_from_enu(home: GeoPoint, east_m: float, north_m: float, up_m: float) -> GeoPoint:
    """The WGS-84 point ``east_m``/``north_m``/``up_m`` away from ``home``."""
    lat_deg = home.lat_deg + north_m / _M_PER_E7 / 1e7
    lon_deg = home.lon_deg + east_m / (_M_PER_E7 * _lon_scale((home.lat_deg + lat_deg) / 2.0)) / 1e7
    return GeoPoint(lat_deg, lon_deg, home.alt_amsl_m + up_m)


def ned_from_enu(east_m: float, north_m: float, up_m: float) -> tuple[float, float, float]:
    """(north, east, down) from (east, north, up)."""
    return (north_m, east_m, -up_m)


def enu_from_ned(north_m: float, east_m: float, down_m: float) -> tuple[float, float, float]:
    """(east, north, up) from (north, east, down)."""
    return (east_m, north_m, -down_m)


def wrap_deg(angle_deg: float) -> float:
    """An angle folded into [0, 360)."""
    wrapped = math.fmod(angle_deg, 360.0)
    if wrapped < 0.0:
        wrapped += 360.0
    return 0.0 if wrapped == 360.0 else wrapped


def wrap_180(angle_deg: float) -> float:
    """An angle folded into [-180, 180)."""
    return wrap_deg(angle_deg + 180.0) - 180.0
