"""Telemetry in bulk: time series, the vehicle's pose, map points and the route.

Samples are buffered and sent as columns (one ``send_columns`` per series) because one
``log`` call per sample is ~200× slower. The route is drawn in chunks of consecutive
samples, each chunk its own entity: a chunk grows every ``route_step`` samples and the
earlier ones stay on screen, so the route is complete at every time cursor without
re-sending all of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import rerun as rr

from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.view.entities import log_route_chunk
from uavtool.view.paths import LOG_TIME, VEHICLE_TIME, Paths

# name of the series → (colour, unit in the legend)
SERIES: dict[str, tuple[tuple[int, int, int], str]] = {
    "altitude_m": ((80, 160, 255), "altitude above home (m)"),
    "speed_m_s": ((255, 170, 40), "ground speed (m/s)"),
    "climb_m_s": ((160, 100, 255), "climb rate (m/s)"),
    "heading_deg": ((255, 90, 90), "heading (deg)"),
    "gimbal_pitch_deg": ((90, 220, 160), "gimbal pitch (deg)"),
    "battery_pct": ((120, 220, 60), "battery (%)"),
}


def set_times(rec: rr.RecordingStream, *, vehicle_ns: int | None, log_ns: int | None) -> None:
    """Set the stream's time for the next ``log`` calls; an unknown time is left out."""
    if vehicle_ns is None:
        rec.disable_timeline(VEHICLE_TIME)
    else:
        rec.set_time(VEHICLE_TIME, duration=np.timedelta64(vehicle_ns, "ns"))
    if log_ns is None:
        rec.disable_timeline(LOG_TIME)
    else:
        rec.set_time(LOG_TIME, timestamp=np.datetime64(log_ns, "ns"))


def log_series_styles(rec: rr.RecordingStream, paths: Paths, *, shade: int = 0) -> None:
    """Names and colours of the telemetry plots; static. A compared mission's series are
    paler and say so in the legend, as both are drawn on the same axes; so do a fleet's
    vehicles' (``paths.uav``), each ``shade`` steps paler than the first."""
    for name, (base_rgb, base_legend) in SERIES.items():
        rgb, legend = base_rgb, base_legend
        if paths.prefix:
            rgb = (rgb[0] // 2 + 64, rgb[1] // 2 + 64, rgb[2] // 2 + 64)
            legend = f"{legend} [{paths.prefix}]"
        if paths.uav:
            rgb = _paler(rgb, shade)
            legend = f"{legend} [{paths.uav}]"
        rec.log(paths.telemetry(name), rr.SeriesLines(colors=[rgb], names=[legend]), static=True)


def _paler(rgb: tuple[int, int, int], steps: int) -> tuple[int, int, int]:
    """``rgb`` mixed with white, a fifth more each step (four steps, then round again)."""
    t = (steps % 4) / 5.0
    r, g, b = (round(c + (255 - c) * t) for c in rgb)
    return (r, g, b)


@dataclass(frozen=True, slots=True)
class Sample:
    """One telemetry snapshot: ENU metres and m/s, degrees, percent."""

    vehicle_ns: int
    log_ns: int | None
    pos_enu_m: tuple[float, float, float]
    vel_enu_m_s: tuple[float, float, float]
    heading_deg: float
    gimbal_pitch_deg: float
    battery_pct: float


class TelemetryLog:
    """Buffers samples and sends them to ``rec``; ``flush`` sends what is pending."""

    def __init__(
        self,
        rec: rr.RecordingStream,
        paths: Paths,
        *,
        route_chunk: int = 64,
        route_step: int = 8,
        route_rgb: tuple[int, int, int] | None = None,
    ) -> None:
        self.rec = rec
        self.paths = paths
        self.route_rgb = route_rgb  # None: the route's own colour
        self.home: GeoPoint | None = None
        self.route_chunk = route_chunk
        self.route_step = route_step
        self.samples = 0
        self.route_points = 0
        self._pending: list[Sample] = []
        self._chunk_index = 0
        self._chunk: list[tuple[float, float, float]] = []
        self._chunk_new = 0  # samples in the chunk not yet drawn

    @property
    def pending(self) -> int:
        """Samples added but not sent yet."""
        return len(self._pending)

    def add(self, sample: Sample) -> None:
        self._pending.append(sample)
        self.samples += 1
        self._route(sample)

    def flush(self) -> None:
        """Send the pending samples as columns, and draw the route up to the last one."""
        if self._chunk_new:
            self._draw_chunk(self._pending[-1] if self._pending else None)
        if not self._pending:
            return
        self._send(self._pending)
        self._pending = []

    def _route(self, sample: Sample) -> None:
        if len(self._chunk) >= self.route_chunk:
            self._draw_chunk(sample)  # close the full chunk at the time of its successor
            last = self._chunk[-1]
            self._chunk_index += 1
            self._chunk = [last]  # the next chunk starts where this one ends: no gap
        self._chunk.append(sample.pos_enu_m)
        self.route_points += 1
        self._chunk_new += 1
        if self._chunk_new >= self.route_step:
            self._draw_chunk(sample)

    def _draw_chunk(self, at: Sample | None) -> None:
        if at is None or len(self._chunk) < 2 or not self._chunk_new:
            return
        set_times(self.rec, vehicle_ns=at.vehicle_ns, log_ns=at.log_ns)
        log_route_chunk(
            self.rec,
            self.paths.route_chunk(self._chunk_index),
            positions_enu_m=np.asarray(self._chunk, dtype=np.float64),
            rgb=self.route_rgb,
        )
        self._chunk_new = 0

    def _send(self, samples: list[Sample]) -> None:
        indexes = [
            rr.TimeColumn(
                VEHICLE_TIME,
                duration=np.array([s.vehicle_ns for s in samples], dtype="timedelta64[ns]"),
            )
        ]
        log_times = [s.log_ns for s in samples]
        if all(t is not None for t in log_times):
            indexes.append(
                rr.TimeColumn(LOG_TIME, timestamp=np.array(log_times, dtype="datetime64[ns]"))
            )
        pos = np.array([s.pos_enu_m for s in samples], dtype=np.float64)
        vel = np.array([s.vel_enu_m_s for s in samples], dtype=np.float64)
        values = {
            "altitude_m": pos[:, 2],
            "speed_m_s": np.hypot(vel[:, 0], vel[:, 1]),
            "climb_m_s": vel[:, 2],
            "heading_deg": np.array([s.heading_deg for s in samples]),
            "gimbal_pitch_deg": np.array([s.gimbal_pitch_deg for s in samples]),
            "battery_pct": np.array([s.battery_pct for s in samples]),
        }
        for name, column in values.items():
            self.rec.send_columns(
                self.paths.telemetry(name),
                indexes=indexes,
                columns=rr.Scalars.columns(scalars=column),
            )
        self.rec.send_columns(
            self.paths.vehicle,
            indexes=indexes,
            columns=rr.Transform3D.columns(
                translation=pos, quaternion=[_yaw_quaternion(s.heading_deg) for s in samples]
            ),
        )
        if self.home is not None:
            home = self.home
            geo = [geo_from_enu(home, *s.pos_enu_m) for s in samples]
            self.rec.send_columns(
                self.paths.map_vehicle,
                indexes=indexes,
                columns=rr.GeoPoints.columns(positions=[(g.lat_deg, g.lon_deg) for g in geo]),
            )


def _yaw_quaternion(heading_deg: float) -> tuple[float, float, float, float]:
    """Body x (forward) along the heading: clockwise from north → counter-clockwise from east."""
    yaw = math.radians(90.0 - heading_deg)
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
