"""The flight description: one frozen value that says what a flight was — the mission and its
parameters, the scene, the vehicle and its faults, the camera — built by ``uavtool fly``,
stored in the recording's metadata and read back by replay, re-fly, view and sweep through
:func:`FlightDescription.from_metadata` alone.

On disk it is the metadata records ``mission``, ``scene``, ``seeds``, ``vehicle`` and
``flight`` (plain strings, as MCAP metadata is), so any MCAP tool shows it. Recordings made
before missions were plug-ins have no mission name: they flew the built-in ``search``.

A recording is untrusted input: every value is checked for type and range here, before any
of it is used (a camera is never opened from a file, an image size is bounded), and a
malformed record is a one-line :class:`~uavtool.errors.InputError` naming the file and field.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, TypeVar

from uavtool.checks import MAX_HOME_M
from uavtool.errors import InputError
from uavtool.plugins import BUILTIN, DEFAULT, MissionRef

T = TypeVar("T")
Metadata = Mapping[str, Mapping[str, str]]

CONNECT_BUILTIN = "builtin"
CLOCKS = ("lockstep", "wall")
SCENE_ORIGINS = ("scene", "vehicle-home", "none")
TARGETS = ("scene", "file", "none")
SIDE_PX = (16, 8192)
"""The image sides a description accepts (as ``uavtool scene --size``): a recording asking
for more is refused before anything is allocated."""
_MAX_JSON = 16 * 1024 * 1024
"""The longest JSON text read from a metadata field (a scene of thousands of buildings is
well under a megabyte)."""


class DescriptionError(InputError):
    """A recording's flight description is missing or malformed."""


@dataclass(frozen=True, slots=True)
class FlightDescription:
    """What a flight was. ``params`` is the mission's parameters as JSON-ready data (decode
    them with the mission's class, :func:`uavtool.plugins.mission_params`); ``scene`` the
    scene as :func:`uavtool.world.scene_to_dict` writes it (None: no scene)."""

    mission: MissionRef
    params: dict[str, Any]
    scene: dict[str, Any] | None
    scene_name: str = ""
    connect: str = CONNECT_BUILTIN
    """``builtin`` for the built-in vehicle, else the connection string."""
    camera: str = "sim"
    clock: str = "lockstep"
    """``lockstep`` (the built-in vehicle: the flight is a function of this description) or
    ``wall``."""
    scene_origin: str = "scene"
    seed: int = 0
    noise: bool = False
    wind: tuple[float, float] = (0.0, 0.0)
    """Speed (m/s) and the direction it blows from (degrees)."""
    link_outages_s: tuple[tuple[float, float], ...] = ()
    """(start, duration) of each link cut, vehicle seconds."""
    vehicle_params: tuple[tuple[str, float], ...] = ()
    hfov_deg: float = 60.0
    size_px: tuple[int, int] = (640, 480)
    target: str = "scene"
    """Where the target picture came from: ``scene`` (rendered), ``file``, or ``none`` (the
    mission needs none)."""
    no_gimbal: bool = False
    vehicles: int = 1
    """How many built-in vehicles flew (a fleet: more than one)."""
    offset_line: tuple[float, float] = (90.0, 10.0)
    """A fleet's homes: vehicle i's is i × spacing (m) from the first's along the bearing
    (degrees): (bearing, spacing)."""
    homes_m: tuple[tuple[float, float], ...] = ()
    """A fleet's homes given one by one (metres east and north of the scene's home), in place
    of the offset line; empty: on the line."""
    tool_version: str = field(default="", compare=False)
    """The uavtool that flew it (not part of what the flight was)."""

    @property
    def builtin(self) -> bool:
        return self.connect == CONNECT_BUILTIN

    def to_metadata(self) -> dict[str, dict[str, str]]:
        """The metadata records, in the order they are written."""
        mission = {"params": json.dumps(self.params), "tool_version": self.tool_version}
        mission |= {
            "name": self.mission.name,
            "class": self.mission.target,
            "version": self.mission.version,
        }
        records: dict[str, dict[str, str]] = {"mission": mission}
        if self.scene is not None:
            records["scene"] = {"name": self.scene_name, "json": json.dumps(self.scene)}
        records["seeds"] = {
            "sitl": str(self.seed),
            "camera_noise": str(self.seed) if self.noise else "",
        }
        records["vehicle"] = {
            "connect": self.connect,
            "builtin": str(self.builtin).lower(),
            "camera": self.camera,
            "clock": self.clock,
            "scene_origin": self.scene_origin,
        }
        records["flight"] = {
            "seed": str(self.seed),
            "noise": json.dumps(self.noise),
            "wind": json.dumps(list(self.wind)),
            "link_outages_s": json.dumps([list(o) for o in self.link_outages_s]),
            "vehicle_params": json.dumps([list(p) for p in self.vehicle_params]),
            "hfov_deg": json.dumps(self.hfov_deg),
            "size_px": json.dumps(list(self.size_px)),
            "target": self.target,
            # Written only when set, so the recordings of flights with a gimbal (the goldens
            # among them) stay as they were.
            **({"no_gimbal": "true"} if self.no_gimbal else {}),
        }
        if self.vehicles > 1 or self.offset_line != (90.0, 10.0) or self.homes_m:  # one: as it was
            records["fleet"] = {
                "vehicles": str(self.vehicles),
                "offset_line": json.dumps(list(self.offset_line)),
                **(
                    {"homes_m": json.dumps([list(h) for h in self.homes_m])} if self.homes_m else {}
                ),
            }
        return records

    @classmethod
    def from_metadata(cls, meta: Metadata, *, source: str) -> FlightDescription:
        """Read back what :meth:`to_metadata` wrote; DescriptionError naming ``source`` and
        the field when a record is missing or a value is malformed."""
        for name in ("mission", "vehicle", "flight"):
            if name not in meta:
                raise DescriptionError(
                    f"{source}: metadata {name!r} is missing: not a flight recorded by "
                    "`uavtool fly`"
                )
        mission, params = mission_of(meta, source=source)
        vehicle, flight = meta["vehicle"], meta["flight"]
        fleet = meta.get("fleet", {})
        r = _Fields(source)
        scene = scene_data(meta, source=source)
        return cls(
            mission=mission,
            params=params,
            scene=scene,
            scene_name=r.text(meta.get("scene", {}), "scene", "name", default=""),
            connect=r.text(vehicle, "vehicle", "connect"),
            camera=r.text(vehicle, "vehicle", "camera"),
            clock=r.choice(vehicle, "vehicle", "clock", CLOCKS),
            scene_origin=r.choice(vehicle, "vehicle", "scene_origin", SCENE_ORIGINS),
            seed=r.value(flight, "flight", "seed", _int),
            noise=r.value(flight, "flight", "noise", _bool),
            wind=r.value(flight, "flight", "wind", _pair),
            link_outages_s=r.value(flight, "flight", "link_outages_s", _outages),
            vehicle_params=r.value(flight, "flight", "vehicle_params", _vehicle_params),
            hfov_deg=r.value(flight, "flight", "hfov_deg", _hfov),
            size_px=r.value(flight, "flight", "size_px", _size),
            target=r.choice(flight, "flight", "target", TARGETS),
            no_gimbal=r.value(flight, "flight", "no_gimbal", _bool, default="false"),
            vehicles=r.value(fleet, "fleet", "vehicles", _vehicles, default="1"),
            offset_line=r.value(fleet, "fleet", "offset_line", _offset_line, default="[90, 10]"),
            homes_m=r.value(fleet, "fleet", "homes_m", _homes, default="[]"),
            tool_version=r.text(meta["mission"], "mission", "tool_version", default=""),
        )


def mission_of(meta: Metadata, *, source: str) -> tuple[MissionRef, dict[str, Any]]:
    """The mission a recording flew and its parameters' JSON (what replay needs alone)."""
    rec = meta.get("mission")
    if rec is None:
        raise DescriptionError(
            f"{source}: metadata 'mission' is missing: not a mission recording (record one "
            "with `uavtool fly`)"
        )
    r = _Fields(source)
    params = r.value(rec, "mission", "params", _json_object)
    name = r.text(rec, "mission", "name", default=DEFAULT)
    target = r.text(rec, "mission", "class", default=BUILTIN[DEFAULT] if name == DEFAULT else "")
    if not target:
        raise DescriptionError(f"{source}: metadata mission.class is missing for {name!r}")
    version = r.text(rec, "mission", "version", default=r.text(rec, "mission", "tool_version", ""))
    return MissionRef(name, target, version), params


def scene_data(meta: Metadata, *, source: str) -> dict[str, Any] | None:
    """The scene's JSON data a recording holds (None when it holds none)."""
    rec = meta.get("scene")
    if rec is None or "json" not in rec:
        return None
    return _Fields(source).value(rec, "scene", "json", _json_object)


class _Fields:
    """Reads one metadata field at a time, naming it in any error."""

    def __init__(self, source: str) -> None:
        self.source = source

    def text(
        self, rec: Mapping[str, str], record: str, key: str, default: str | None = None
    ) -> str:
        value = rec.get(key, default)
        if value is None:
            raise DescriptionError(f"{self.source}: metadata {record}.{key} is missing")
        if not isinstance(value, str):
            raise DescriptionError(f"{self.source}: metadata {record}.{key} is not text")
        return value

    def choice(
        self, rec: Mapping[str, str], record: str, key: str, allowed: tuple[str, ...]
    ) -> str:
        value = self.text(rec, record, key)
        if value not in allowed:
            raise DescriptionError(
                f"{self.source}: metadata {record}.{key}={value[:40]!r}: expected one of "
                f"{', '.join(allowed)}"
            )
        return value

    def value(
        self,
        rec: Mapping[str, str],
        record: str,
        key: str,
        parse: Callable[[str], T],
        default: str | None = None,
    ) -> T:
        text = self.text(rec, record, key, default)
        try:
            return parse(text)
        except (ValueError, TypeError, RecursionError) as exc:
            why = "nested too deeply" if isinstance(exc, RecursionError) else str(exc)
            raise DescriptionError(
                f"{self.source}: metadata {record}.{key} is malformed: {why[:120]}"
            ) from None


def _json(text: str) -> Any:
    if len(text) > _MAX_JSON:
        raise ValueError(f"{len(text)} characters, more than {_MAX_JSON}")
    return json.loads(text)


def _json_object(text: str) -> dict[str, Any]:
    value = _json(text)
    if not isinstance(value, dict):
        raise ValueError("expected a JSON object")
    return value


def _number(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{value!r:.40} is not a number")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{value!r:.40} is not finite")
    return number


def _int(text: str) -> int:
    if not text.lstrip("-").isdigit() or len(text) > 20:
        raise ValueError(f"{text!r:.40} is not an integer")
    return int(text)


MAX_FLEET = 64
"""The most vehicles a recording may say flew (as many as ``uavtool sitl`` serves)."""


def _vehicles(text: str) -> int:
    n = _int(text)
    if not 1 <= n <= MAX_FLEET:
        raise ValueError(f"{n} vehicles: expected 1 to {MAX_FLEET}")
    return n


def _offset_line(text: str) -> tuple[float, float]:
    value = _json(text)
    if not (isinstance(value, list) and len(value) == 2):
        raise ValueError("expected [bearing, spacing]")
    bearing, spacing = _number(value[0]), _number(value[1])
    if not 0.0 < spacing <= 1000.0:
        raise ValueError(f"spacing {spacing:g} m: expected (0, 1000]")
    return bearing, spacing


def _homes(text: str) -> tuple[tuple[float, float], ...]:
    value = _json(text)
    if not isinstance(value, list) or len(value) > MAX_FLEET:
        raise ValueError(f"expected a list of at most {MAX_FLEET} [east, north] pairs")
    homes = []
    for home in value:
        if not (isinstance(home, list) and len(home) == 2):
            raise ValueError("expected [east, north] pairs")
        east, north = _number(home[0]), _number(home[1])
        if max(abs(east), abs(north)) > MAX_HOME_M:
            raise ValueError(f"home {east:g},{north:g}: more than {MAX_HOME_M:g} m from the scene")
        homes.append((east, north))
    return tuple(homes)


def _bool(text: str) -> bool:
    value = _json(text)
    if not isinstance(value, bool):
        raise ValueError(f"{text!r:.40} is not true or false")
    return value


def _pair(text: str) -> tuple[float, float]:
    value = _json(text)
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError("expected [speed, direction]")
    return _number(value[0]), _number(value[1])


def _outages(text: str) -> tuple[tuple[float, float], ...]:
    value = _json(text)
    if not isinstance(value, list):
        raise ValueError("expected a list of [start, duration]")
    out = []
    for item in value:
        if not isinstance(item, list) or len(item) != 2:
            raise ValueError("expected [start, duration]")
        start, duration = _number(item[0]), _number(item[1])
        if not (0.0 <= start <= 1e6 and 0.0 < duration <= 1e6):
            raise ValueError(f"outage {start:g}:{duration:g} is outside 0..1e6 s")
        out.append((start, duration))
    return tuple(out)


def _vehicle_params(text: str) -> tuple[tuple[str, float], ...]:
    value = _json(text)
    if not isinstance(value, list):
        raise ValueError("expected a list of [NAME, value]")
    out = []
    for item in value:
        if not isinstance(item, list) or len(item) != 2 or not isinstance(item[0], str):
            raise ValueError("expected [NAME, value]")
        out.append((item[0], _number(item[1])))
    return tuple(out)


def _hfov(text: str) -> float:
    value = _number(_json(text))
    if not 1.0 <= value <= 170.0:
        raise ValueError(f"{value:g}° is outside 1..170")
    return value


def _size(text: str) -> tuple[int, int]:
    value = _json(text)
    if not isinstance(value, list) or len(value) != 2 or not all(type(v) is int for v in value):
        raise ValueError("expected [width, height] in pixels")
    w, h = value
    lo, hi = SIDE_PX
    if not (lo <= w <= hi and lo <= h <= hi):
        raise ValueError(f"{w}x{h} is outside {lo}..{hi} pixels a side")
    return w, h
