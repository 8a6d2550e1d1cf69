"""The mission's parameters: one typed, documented structure, recorded with every mission.

``Params`` groups the mission's own settings with those of each vision and navigation stage it
calls. Keys are dotted paths (``mission.look_fill``, ``vectorize.rdp_epsilon_px``,
``viewpoints.safety_margin_m``) for ``--set key=value`` on ``fly`` and ``replay``.
"""

from __future__ import annotations

import dataclasses
import difflib
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, ClassVar, TypeVar, overload

from uavtool.checks import (
    DN,
    FRACTION,
    NON_NEGATIVE,
    POSITIVE,
    Range,
    check_fields,
    coerce,
    field_hint,
)
from uavtool.errors import InputError
from uavtool.nav import ViewpointParams
from uavtool.vision import ModelParams, RecognizeParams, VectorizeParams

# Ranges shared by several fields; the upper bounds keep every value sendable as MAVLink's
# float32 and far beyond any sensible flight.
_LENGTH_M = Range(0.0, 10_000.0, lo_open=True)
_GAP_M = Range(0.0, 10_000.0)
_FILL = Range(0.0, 1.0, lo_open=True)
_SPEED_M_S = Range(0.0, 100.0, lo_open=True)
_WAIT_S = Range(0.0, 86_400.0)
_TIMEOUT_S = Range(0.0, 86_400.0, lo_open=True)


@dataclass(frozen=True, slots=True)
class FlightParams:
    """How any mission flies and how patient it is, read by :class:`~uavtool.mission.base.
    FlightMission`'s helpers (moves, photos, commands, take-off, landing). Distances in
    metres, times in seconds of vehicle time (the telemetry's ``time_boot_ms``), angles in
    degrees. A mission's parameters hold one of these as a group (the built-in mission's is
    ``mission``, a plug-in's usually ``flight``)."""

    gimbal: bool = True
    """The vehicle can point its camera. Without a gimbal (``uavtool fly --no-gimbal``) the
    camera is fixed straight down and no gimbal command is sent (the built-in mission flies
    its search, and ends at the match as partial: the side photos need a gimbal)."""
    arrive_radius_m: float = 0.6
    """A position counts as reached within this distance …"""
    arrive_speed_m_s: float = 0.3
    """… and below this ground speed (so the photo is not blurred by motion)."""
    heading_tolerance_deg: float = 3.0
    """A commanded heading counts as reached within this."""
    gimbal_tolerance_deg: float = 2.0
    """A commanded gimbal pitch counts as reached within this."""
    cruise_speed_m_s: float = 5.0
    """Slowest speed a move is expected to make: its timeout is distance / this + slack."""
    climb_speed_m_s: float = 1.0
    """Slowest climb or descent rate expected (the timeout of take-off and of every move's
    vertical part)."""
    move_slack_s: float = 20.0
    """Extra time allowed for any move, climb or turn before it counts as failed."""
    retry_wait_s: float = 2.0
    """Pause before a refused command is tried again."""
    arm_wait_s: float = 60.0
    """Arming is retried this long (pre-arm checks may need time after boot)."""
    command_retries: int = 3
    """A refused or unanswered command (or a move that times out) is retried this many times,
    then the mission aborts with RTL."""
    link_lost_abort_s: float = 30.0
    """Silence from the vehicle for longer than this ends the mission (the vehicle's own
    failsafe flies it); shorter losses are waited out and the mission resumes."""
    land_timeout_s: float = 300.0
    """Time allowed for the return and landing before the mission stops watching."""

    RANGES: ClassVar[Mapping[str, Range]] = MappingProxyType(
        {
            "arrive_radius_m": _LENGTH_M,
            "arrive_speed_m_s": _SPEED_M_S,
            "heading_tolerance_deg": Range(0.0, 180.0, lo_open=True),
            "gimbal_tolerance_deg": Range(0.0, 90.0, lo_open=True),
            "cruise_speed_m_s": _SPEED_M_S,
            "climb_speed_m_s": _SPEED_M_S,
            "move_slack_s": _WAIT_S,
            "retry_wait_s": _WAIT_S,
            "arm_wait_s": _WAIT_S,
            "command_retries": Range(0, 100),
            "link_lost_abort_s": _TIMEOUT_S,
            "land_timeout_s": _TIMEOUT_S,
        }
    )
    """Allowed values of each field (floats must also be finite)."""

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="flight")


@dataclass(frozen=True, slots=True)
class MissionParams(FlightParams):
    """What the mission does and how patient it is. Distances in metres, times in seconds
    of vehicle time (the telemetry's ``time_boot_ms``), angles in degrees."""

    overview_alt_m: float = 45.0
    """Altitude above home of the first overview photo."""
    overview_climb_m: float = 15.0
    """The second overview photo is taken at least this much higher, straight above the
    first: a roof's size and place change between them by how far below the camera it is,
    which gives every building's roof height …"""
    search_radius_m: float = 40.0
    """… and high enough to see the whole search area: a square this many metres from home
    east, west, north and south (both overviews are taken straight down, facing whichever of
    north, east, south and west is nearest the vehicle's heading; the photo's shorter side
    spans the square)."""
    assumed_roof_m: float = 25.0
    """Roof height assumed for a building whose height the overview photos could not measure
    (cut by the border, or seen in one photo only): the tallest expected. A look measures it."""
    roof_match_px: float = 25.0
    """A roof in the lower overview is the same as one in the higher when it lies within
    this many pixels of where the climb should have moved it (and has its colour)."""
    look_fill: float = 0.5
    """Each nadir look at a point of interest is taken from the altitude at which the
    building's footprint spans this fraction of the photo's shorter side …"""
    top_fill: float = 0.6
    """… and the top photo for the model from the altitude at which it spans this fraction."""
    min_above_roof_m: float = 6.0
    """No photo is taken closer than this above the roof it looks at."""
    diagonal_open_beneath: float = 0.15
    """When the model from the top, front and right photos is open under at least this
    fraction of its largest section (just above the ground: the side photos saw through under
    the building), a third side photo from a diagonal carves what they could not see through,
    and the model is built again with it (above 1 = never)."""
    roof_gap_px: float = 6.0
    """Same-coloured roofs closer than this (pixels) in a nadir photo are one building: blocks
    of different heights show as separate roofs split by a strip of wall."""
    roof_colour_tolerance_dn: float = 10.0
    """Roofs count as one colour for that when their colours differ by at most this in every
    RGB channel (0–255): sensor noise gives one building's roofs slightly different colours
    (0 = only equal colours)."""
    match_hue_tolerance_deg: float = 20.0
    """A candidate whose colour's hue is further than this from the target's is not a match,
    whatever its shape (0 = judge by shape alone)."""
    min_poi_area_px: float = 150.0
    """Overview shapes smaller than this (square pixels) are not visited, unless cut by the
    photo's border (a building reaching out of the frame shows any part of itself) or of the
    target's colour (within ``match_hue_tolerance_deg``: a small target)."""
    max_looks: int = 3
    """Photos taken at most at one point of interest. When a look is doubtful — the candidate
    has the target's hue but its outline is cut by the image border, or it scores between
    ``recheck_min_score`` and the threshold, or it lies off the photo's centre — the vehicle
    climbs ``recheck_climb_m`` over the candidate's roof and looks again; the first match
    counts (1 = never look again)."""
    recheck_min_score: float = 0.4
    """Lowest score that makes a candidate worth a second look."""
    recheck_offcentre: float = 0.25
    """A candidate whose centroid is further than this fraction of the photo's half-height
    from the centre is off-centre."""
    recheck_climb_m: float = 10.0
    """Each further look is taken this much higher than the one before (the whole roof in
    view, smaller perspective steps between its heights; never above the second overview)."""
    visit_all: bool = False
    """Visit every point of interest even after a match (then keep the best-scoring match)."""
    RANGES: ClassVar[Mapping[str, Range]] = MappingProxyType(
        {
            "overview_alt_m": _LENGTH_M,
            "overview_climb_m": _LENGTH_M,
            "search_radius_m": _LENGTH_M,
            "assumed_roof_m": _GAP_M,
            "roof_match_px": POSITIVE,
            "look_fill": _FILL,
            "top_fill": _FILL,
            "min_above_roof_m": _LENGTH_M,
            "diagonal_open_beneath": NON_NEGATIVE,
            "roof_gap_px": NON_NEGATIVE,
            "roof_colour_tolerance_dn": DN,
            "match_hue_tolerance_deg": Range(0.0, 180.0),
            "min_poi_area_px": NON_NEGATIVE,
            "max_looks": Range(1, 100),
            "recheck_min_score": FRACTION,
            "recheck_offcentre": NON_NEGATIVE,
            "recheck_climb_m": _GAP_M,
            **FlightParams.RANGES,
        }
    )
    """Allowed values of each field (floats must also be finite)."""

    def __post_init__(self) -> None:
        check_fields(self, self.RANGES, group="mission")
        if not self.assumed_roof_m < self.overview_alt_m:
            raise InputError(
                "mission.assumed_roof_m must be below mission.overview_alt_m, "
                f"got {self.assumed_roof_m}"
            )


@dataclass(frozen=True, slots=True)
class Params:
    """Everything that shapes the mission's decisions (recorded as metadata ``mission``)."""

    mission: MissionParams = field(default_factory=MissionParams)
    vectorize: VectorizeParams = field(default_factory=lambda: VectorizeParams(roof_only=True))
    """Vectorization of nadir photos (overview, points of interest, top)."""
    side_vectorize: VectorizeParams = field(default_factory=VectorizeParams)
    """Vectorization of the front and right photos (walls, not only roofs)."""
    recognize: RecognizeParams = field(default_factory=lambda: RecognizeParams(threshold=0.7))
    """Shape matching. The threshold is lower than the matcher's default: at the detail
    altitude a building's roofs at different heights are seen with perspective steps
    between them (on ``paper`` the target scores 0.74–0.77, the other buildings ≤ 0.45)."""
    model: ModelParams = field(default_factory=ModelParams)
    viewpoints: ViewpointParams = field(default_factory=ViewpointParams)


P = TypeVar("P")


def to_dict(params: Any) -> dict[str, Any]:
    """A JSON-ready nested dict (tuples become lists) of any mission's parameters: a frozen
    dataclass whose fields are groups (frozen dataclasses) of values, as :class:`Params`."""
    return json.loads(json.dumps(dataclasses.asdict(params)))  # type: ignore[no-any-return]


@overload
def from_dict(data: dict[str, Any], *, source: str = ...) -> Params: ...
@overload
def from_dict(data: dict[str, Any], root: type[P], *, source: str = ...) -> P: ...
def from_dict(data: dict[str, Any], root: type[Any] = Params, *, source: str = "parameters") -> Any:
    """The inverse of :func:`to_dict` (for the parameters type ``root``); unknown keys are
    errors listing the valid ones."""
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected a mapping of parameter groups")
    return _apply(root(), _flatten(data), source=source)


def with_overrides(params: P, pairs: dict[str, Any], *, source: str = "--set") -> P:
    """``params`` with keys set: dotted (``{"mission.look_fill": "0.6"}``, values as strings
    or JSON types) or nested (``{"mission": {"look_fill": 0.6}}``, as a params file holds)."""
    return _apply(params, _flatten(pairs), source=source)


def parse_settings(texts: Iterable[str], *, option: str = "--set") -> dict[str, str]:
    """``["mission.look_fill=0.6", …]`` → ``{"mission.look_fill": "0.6", …}``."""
    out: dict[str, str] = {}
    for text in texts:
        key, sep, value = text.partition("=")
        if not sep:
            raise InputError(f"{option} {text!r}: expected KEY=VALUE")
        out[key.strip()] = value.strip()
    return out


def valid_keys(root: type[Any] = Params) -> tuple[str, ...]:
    """Every dotted key that ``--set`` accepts for the parameters type ``root``."""
    return tuple(_flatten(to_dict(root())))


def _flatten(data: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"group": {"name": v}}`` → ``{"group.name": v}``; deeper mappings stay values (no
    parameter is one, so they are refused by name, never recursed into)."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict) and not prefix:
            out.update(_flatten(value, f"{path}."))
        else:
            out[path] = value
    return out


def _suggest(key: str, known: tuple[str, ...]) -> str:
    """The closest valid keys; else the keys of the key's group; else the groups."""
    close = difflib.get_close_matches(key, known, n=3, cutoff=0.75)
    if not close:  # the right name in the wrong group
        name = key.rsplit(".", 1)[-1]
        names = difflib.get_close_matches(name, [k.split(".", 1)[1] for k in known], cutoff=0.75)
        close = [k for k in known if k.split(".", 1)[1] in names][:3]
    if close:
        return f"did you mean {' or '.join(close)}?"
    group = key.split(".", 1)[0]
    same = [k for k in known if k.startswith(group + ".")]
    if same:
        return f"valid {group} keys: {', '.join(k.split('.', 1)[1] for k in same)}"
    groups = sorted({k.split(".", 1)[0] for k in known})
    return f"keys are GROUP.NAME with GROUP one of {', '.join(groups)}"


def _apply(params: P, pairs: dict[str, Any], *, source: str) -> P:
    grouped: dict[str, dict[str, Any]] = {}
    known = valid_keys(type(params))
    for key, raw in pairs.items():
        if key not in known:
            raise InputError(f"{source}: unknown parameter {key!r}; {_suggest(key, known)}")
        group, name = key.split(".", 1)
        cls = type(getattr(params, group))
        ranges: Mapping[str, Range] = getattr(cls, "RANGES", {})
        try:
            value = coerce(raw, field_hint(cls, name), name=key, bounds=ranges.get(name, Range()))
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None
        grouped.setdefault(group, {})[name] = value
    changed: dict[str, Any] = {}
    for group, values in grouped.items():
        try:
            changed[group] = dataclasses.replace(getattr(params, group), **values)
        except (InputError, ValueError) as exc:  # a plug-in's own checks raise ValueError
            raise InputError(f"{source}: {exc}") from None
    return dataclasses.replace(params, **changed)  # type: ignore[type-var]
