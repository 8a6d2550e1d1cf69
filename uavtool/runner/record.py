"""What a flight writes into its recording, on which topics (docs/recording-format.md).

The authoritative streams are ``/mission/observations`` (every observation, in the order the
mission consumed it, numbered by ``step``) and ``/mission/outputs`` (every output, numbered by
``n``, with the ``step`` that produced it): replay reads these. Photos go to ``/camera/*``,
telemetry also to ``/vehicle/*``, events also to ``/mission/events`` and the model's GLB to
``/mission/model``, and the route flown, photo poses, points of interest and viewpoints to
``/mission/scene`` (markers), so Foxglove, Lichtblick and Rerun show them natively.

The clock rule: every message's ``log_time`` is when the runner received or produced it on the
recording's clock — for a simulated flight flown in lockstep, the vehicle's time since boot
plus a fixed epoch (``uavtool.sitl.lockstep.SIM_EPOCH_NS``); for any other vehicle, the wall
clock. ``publish_time`` equals ``log_time`` on every channel. The vehicle's own time since
boot is in the payloads (``time_boot_ms``).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable
from typing import Any

from uavtool.camera import CameraPose, Intrinsics
from uavtool.geo import GeoPoint
from uavtool.mission import Level, Observation, Output, Photo, Telemetry
from uavtool.mission.codec import encode_observation, encode_output, output_bytes
from uavtool.mission.schema import observation_schema, output_schema
from uavtool.recording import (
    CameraCalibration,
    CompressedImage,
    FrameTransform,
    LogEntry,
    LogLevel,
    Model3D,
    RgbImage,
    SceneMarkers,
    TriangleMesh,
)
from uavtool.recording.protocol import MessageWriter
from uavtool.recording.topics import (
    CALIBRATION,
    CAMERA_POSE,
    EVENTS,
    IMAGE,
    MODEL,
    OBSERVATIONS,
    OUTPUTS,
    PICTURES,
    SCENE,
    TARGET,
)
from uavtool.runner.markers import RouteMarkers

_LEVELS = {Level.INFO: LogLevel.INFO, Level.WARNING: LogLevel.WARNING, Level.ERROR: LogLevel.ERROR}


ClockNs = Callable[[], int]
"""The recording's clock, integer ns since the Unix epoch (``time.time_ns`` for a real vehicle)."""


def write_camera_frame(
    writer: MessageWriter,
    png: bytes | RgbImage,
    intrinsics: Intrinsics,
    pose: CameraPose,
    log_time_ns: int,
) -> None:
    """One camera frame on ``/camera/image``, with its calibration and its pose; ``png`` may be
    the raw frame, which the writer encodes."""
    t = log_time_ns
    image = CompressedImage(png) if isinstance(png, bytes) else CompressedImage(b"", raw=png)
    writer.write(IMAGE, image, log_time_ns=t)
    writer.write(CALIBRATION, CameraCalibration.from_intrinsics(intrinsics), log_time_ns=t)
    writer.write(CAMERA_POSE, FrameTransform.from_camera_pose(pose), log_time_ns=t)


class MissionRecorder:
    """Writes a flight into ``writer``, each message stamped by ``clock_ns``. ``home`` is the
    vehicle's home (for WGS-84 fixes)."""

    def __init__(self, writer: MessageWriter, *, clock_ns: ClockNs = time.time_ns) -> None:
        self.writer = writer
        self.clock_ns = clock_ns
        self.home: GeoPoint | None = None
        writer.add_json_topic(
            OBSERVATIONS, schema_name="uavtool.Observation", schema=observation_schema()
        )
        writer.add_json_topic(OUTPUTS, schema_name="uavtool.Output", schema=output_schema())
        self._outputs = 0
        self._markers = RouteMarkers()
        self.mavlink = writer.mavlink_tap(clock_ns)
        """The link's tap (:data:`~uavtool.link.client.Tap`): every frame, as it crossed."""

    def target(self, png: bytes) -> None:
        self.writer.write(
            TARGET, CompressedImage(png, frame_id="target"), log_time_ns=self.clock_ns()
        )

    def observation(self, step: int, obs: Observation, png: bytes | None = None) -> None:
        """Record one observation; a photo's frame as ``png`` if the caller encoded it, else
        the writer encodes it (a writer process off the flight's path)."""
        t = self.clock_ns()
        if isinstance(obs, Photo):
            image: bytes | RgbImage = png if png is not None else _raw(obs.image_rgb)
            write_camera_frame(self.writer, image, obs.intrinsics, obs.pose, t)
            self._scene(self._markers.photo(obs.pose), t)
        elif isinstance(obs, Telemetry):
            self._markers.telemetry(obs.pos_enu_m)
            self.writer.write_vehicle(obs.pos_enu_m, obs.heading_deg, self.home, log_time_ns=t)
        values = telemetry_values(step, obs) if isinstance(obs, Telemetry) else None
        if values is not None:
            self.writer.write_json_format(OBSERVATIONS, TELEMETRY_TEMPLATE, values, log_time_ns=t)
            return
        payload = {"step": step, **encode_observation(obs)}
        self.writer.write_json(OBSERVATIONS, payload, log_time_ns=t)

    def outputs(self, step: int, outputs: list[Output]) -> None:
        """Write the outputs of one mission step."""
        t = self.clock_ns()
        for out in outputs:
            self._outputs += 1
            data, blob = encode_output(out), output_bytes(out)
            self.write_output(self._outputs, step, data, blob=blob, log_time_ns=t)

    def write_output(
        self,
        n: int,
        step: int,
        data: dict[str, Any],
        *,
        blob: bytes | None = None,
        log_time_ns: int,
    ) -> None:
        """One output in its JSON form (``n``, ``step``, ``encode_output``), plus its Foxglove
        view: an event as a log line, a model's mesh as a 3D model (its GLB made by the
        writer), a picture's PNG (``blob``) as an image."""
        self.writer.write_json(
            OUTPUTS,
            {"n": n, "step": step, **data},
            log_time_ns=log_time_ns,
        )
        if data.get("type") == "Event":
            entry = LogEntry(_LEVELS[Level(data["level"])], str(data["text"]))
            self.writer.write(EVENTS, entry, log_time_ns=log_time_ns)
        elif data.get("type") == "ModelBuilt":
            mesh = TriangleMesh(
                tuple(tuple(v) for v in data["vertices_m"]), tuple(tuple(f) for f in data["faces"])
            )
            self.writer.write(MODEL, Model3D(b"", mesh=mesh), log_time_ns=log_time_ns)
        elif blob is not None and data.get("type") == "Picture":
            picture = CompressedImage(blob, frame_id=str(data.get("tag", "")))
            self.writer.write(PICTURES, picture, log_time_ns=log_time_ns)
        self._scene(self._markers.output(data), log_time_ns)

    def _scene(self, markers: SceneMarkers | None, t_ns: int) -> None:
        if markers is not None:
            self.writer.write(SCENE, markers, log_time_ns=t_ns)

    def note(self, level: Level, text: str, *, name: str = "runner") -> None:
        """A runner event (connection, vehicle STATUSTEXT …) on the events topic only."""
        self.writer.write(
            EVENTS, LogEntry(_LEVELS[level], text, name=name), log_time_ns=self.clock_ns()
        )

    def outcome(self, record: dict[str, Any]) -> None:
        self.writer.add_metadata("outcome", {k: _text(v) for k, v in record.items()})


_TELEMETRY_FIELDS = (
    "time_boot_ms",
    "pos_enu_m",
    "vel_enu_m_s",
    "heading_deg",
    "mode",
    "armed",
    "landed",
    "gimbal_pitch_deg",
    "gimbal_yaw_deg",
    "battery_pct",
)
TELEMETRY_TEMPLATE = (
    '{"step":%d,"type":"Telemetry","time_boot_ms":%d,"pos_enu_m":[%r,%r,%r],'
    '"vel_enu_m_s":[%r,%r,%r],"heading_deg":%r,"mode":%s,"armed":%s,"landed":%s,'
    '"gimbal_pitch_deg":%r,"gimbal_yaw_deg":%r,"battery_pct":%d}'
)
_BOOL = {True: "true", False: "false"}
_encode_str: Callable[[str], str] = json.encoder.encode_basestring


def telemetry_json(step: int, t: Telemetry) -> bytes | None:
    """``dumps({"step": step, **encode_observation(t)})`` byte for byte in less than half the time
    (a flight records thousands of samples), or None when a value is not of the plain type
    the template writes (a numpy number, a NaN: the general path then decides) or
    `Telemetry`'s fields are not the ones it knows."""
    values = telemetry_values(step, t)
    return None if values is None else (TELEMETRY_TEMPLATE % values).encode()


def telemetry_values(step: int, t: Telemetry) -> tuple[Any, ...] | None:
    """What `TELEMETRY_TEMPLATE` formats into `telemetry_json`'s bytes (a writer process
    does the formatting, off the flight's path), or None where `telemetry_json` is None."""
    p, v = t.pos_enu_m, t.vel_enu_m_s
    if _FIELDS_NOW != _TELEMETRY_FIELDS or len(p) != 3 or len(v) != 3:
        return None
    floats = (*p, *v, t.heading_deg, t.gimbal_pitch_deg, t.gimbal_yaw_deg)
    if not (
        type(step) is int
        and type(t.time_boot_ms) is int
        and type(t.battery_pct) is int
        and type(t.mode) is str
        and type(t.armed) is bool
        and type(t.landed) is bool
        and all(type(x) is float for x in floats)
        and math.isfinite(sum(floats))
    ):
        return None
    return (
        step,
        t.time_boot_ms,
        *p,
        *v,
        t.heading_deg,
        _encode_str(t.mode),
        _BOOL[t.armed],
        _BOOL[t.landed],
        t.gimbal_pitch_deg,
        t.gimbal_yaw_deg,
        t.battery_pct,
    )


_FIELDS_NOW = tuple(f.name for f in dataclasses.fields(Telemetry))


def _raw(rgb: Any) -> RgbImage:
    height, width = rgb.shape[:2]
    return RgbImage(rgb.tobytes(), int(height), int(width))


def _text(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value)
