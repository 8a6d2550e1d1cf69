"""Frames and units: the one place that converts between WGS-84, local NED and local ENU.

Inside uavtool, positions are metres in a local **ENU** frame around home (x east, y north,
z up); MAVLink speaks **NED** for local positions and WGS-84 (degrees ×1e7, millimetres) for
global ones. Headings are degrees clockwise from north in [0, 360).

Global ↔ local uses ArduPilot's own flat-earth scaling (``Location::get_distance_NE`` /
``offset``): exact enough for the few hundred metres a mission spans, and identical to what
an ArduPilot vehicle computes, so offsets agree with ArduPilot's SITL to the millimetre.
Longitudes wrap as ArduPilot's ``diff_longitude`` and ``wrap_longitude`` wrap them: a point
across the 180th meridian is a few metres east, not 40,000 km west, and every longitude
made here is in [-180, 180].
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
    """Local ENU metres of ``point`` relative to ``home`` (up = altitude difference); the
    longitudes' difference the short way round."""
    d_lat_e7 = (point.lat_deg - home.lat_deg) * 1e7
    d_lon_e7 = diff_lon_deg(point.lon_deg, home.lon_deg) * 1e7
    north_m = d_lat_e7 * _M_PER_E7
    east_m = d_lon_e7 * _M_PER_E7 * _lon_scale((home.lat_deg + point.lat_deg) / 2.0)
    return (east_m, north_m, point.alt_amsl_m - home.alt_amsl_m)


def geo_from_enu(home: GeoPoint, east_m: float, north_m: float, up_m: float) -> GeoPoint:
    """The WGS-84 point ``east_m``/``north_m``/``up_m`` away from ``home``."""
    lat_deg = home.lat_deg + north_m / _M_PER_E7 / 1e7
    lon_deg = home.lon_deg + east_m / (_M_PER_E7 * _lon_scale((home.lat_deg + lat_deg) / 2.0)) / 1e7
    return GeoPoint(lat_deg, wrap_lon_deg(lon_deg), home.alt_amsl_m + up_m)


def diff_lon_deg(lon_deg: float, from_lon_deg: float) -> float:
    """``lon_deg - from_lon_deg`` the short way round, in [-180, 180] (ArduPilot's
    ``Location::diff_longitude``)."""
    d = lon_deg - from_lon_deg
    if d > 180.0:
        return d - 360.0
    if d < -180.0:
        return d + 360.0
    return d


def wrap_lon_deg(lon_deg: float) -> float:
    """A longitude that went past ±180 brought back into [-180, 180] (ArduPilot's
    ``Location::wrap_longitude``); one inside is returned as it is, bit for bit."""
    if lon_deg > 180.0:
        return lon_deg - 360.0
    if lon_deg < -180.0:
        return lon_deg + 360.0
    return lon_deg


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
