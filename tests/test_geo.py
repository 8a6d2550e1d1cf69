"""Geo maths anywhere on Earth: across the 180th meridian either way, at the equator, to
85° of latitude north and south, as ArduPilot's ``Location`` computes it."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uavtool.geo import GeoPoint, diff_lon_deg, enu_from_geo, geo_from_enu, wrap_lon_deg

# ArduPilot's LOCATION_SCALING_FACTOR_INV: 1e-7 degree of latitude per metre
_E7_PER_M = 89.83204953368922


def _ardupilot_offset(home: GeoPoint, east_m: float, north_m: float) -> tuple[int, int]:
    """ArduPilot's ``Location::offset`` in its own integer arithmetic (lat, lon in 1e-7°)."""
    lat_e7, lon_e7 = home.lat_e7, home.lon_e7
    d_lat = int(north_m * _E7_PER_M)
    d_lon = int(east_m * _E7_PER_M / max(math.cos(math.radians((lat_e7 + d_lat / 2) * 1e-7)), 0.01))
    lon = lon_e7 + d_lon
    if lon > 1_800_000_000:
        lon -= 3_600_000_000
    elif lon < -1_800_000_000:
        lon += 3_600_000_000
    return lat_e7 + d_lat, lon


@pytest.mark.parametrize(
    ("home_lon", "east_m", "across"),
    [
        (179.999888, 20.0, True),  # 8 m west of the line at 50° N, 20 m east: across it
        (-179.999888, -20.0, True),  # the same, westward
        (179.999888, -20.0, False),
        (0.0, 20.0, False),  # Greenwich: a sign change that is not a wrap
        (0.0, -20.0, False),
    ],
)
def test_a_point_across_the_date_line_is_metres_away_not_the_world(
    home_lon: float, east_m: float, across: bool
) -> None:
    home = GeoPoint(50.0647, home_lon, 219.0)
    point = geo_from_enu(home, east_m, 7.0, 3.0)
    assert -180.0 <= point.lon_deg <= 180.0
    assert (abs(point.lon_deg - home_lon) > 180.0) == across  # the number jumps, not the place
    east, north, up = enu_from_geo(home, point)
    assert (east, north, up) == pytest.approx((east_m, 7.0, 3.0), abs=1e-6)
    lat_e7, lon_e7 = _ardupilot_offset(home, east_m, 7.0)  # what ArduPilot would compute
    assert abs(point.lat_e7 - lat_e7) <= 1 and abs(point.lon_e7 - lon_e7) <= 2


@settings(max_examples=300, deadline=None)
@given(
    lat=st.floats(-85.0, 85.0),
    lon=st.floats(-180.0, 180.0),
    east=st.floats(-2000.0, 2000.0),
    north=st.floats(-2000.0, 2000.0),
)
def test_anywhere_to_85_degrees_round_trips_to_the_millimetre(
    lat: float, lon: float, east: float, north: float
) -> None:
    home = GeoPoint(lat, lon, 100.0)
    point = geo_from_enu(home, east, north, 0.0)
    assert -180.0 <= point.lon_deg <= 180.0
    e, n, _ = enu_from_geo(home, point)
    assert math.hypot(e - east, n - north) < 1e-3


def test_inside_the_range_nothing_changes_bit_for_bit() -> None:
    """Flights that never come near the line give the very same numbers (and files)."""
    for lon in (-179.9, -1e-9, 0.0, 19.945, 179.99):
        assert wrap_lon_deg(lon) == lon
        assert diff_lon_deg(lon, lon - 0.3) == lon - (lon - 0.3)
    assert wrap_lon_deg(180.5) == pytest.approx(-179.5)
    assert wrap_lon_deg(-180.5) == pytest.approx(179.5)
    assert diff_lon_deg(-179.9, 179.9) == pytest.approx(0.2)
    assert diff_lon_deg(179.9, -179.9) == pytest.approx(-0.2)
