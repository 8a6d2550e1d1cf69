"""Missions by name: the built-in ones, and those installed packages register.

A package registers a mission as pytest registers its plug-ins, through an entry-point group
in its ``pyproject.toml``::

    [project.entry-points."uavtool.missions"]
    orbit = "my_package.orbit:OrbitMission"

``uavtool fly --mission orbit`` then flies it; ``--mission my_package.orbit:OrbitMission``
works without registering. A recording names the mission it flew (:class:`MissionRef`) and
replay, re-fly and sweep find the same class again from it.
"""

from __future__ import annotations

import importlib
import re
import sys
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from uavtool import __version__
from uavtool.errors import FailureError, InputError, UavtoolError
from uavtool.mission.base import FlightMission, MissionInputs
from uavtool.mission.fleet import FleetMember
from uavtool.mission.observations import Observation
from uavtool.mission.outputs import Output
from uavtool.mission.params import FlightParams, from_dict

T = TypeVar("T")

GROUP = "uavtool.missions"
"""The entry-point group installed packages register their missions in."""
DEFAULT = "search"

BUILTIN: dict[str, str] = {
    "search": "uavtool.mission.mission:SearchMission",
    "survey": "uavtool.examples.survey:SurveyMission",
    "orbit": "uavtool.examples.orbit:OrbitMission",
    "fleet-survey": "uavtool.examples.fleet_survey:FleetSurveyMission",
    "fleet-search": "uavtool.mission.fleet_search:FleetSearchMission",
}
"""The missions uavtool ships: the paper's search-and-model (and the same for a fleet), and
three examples written on the public API alone (:mod:`uavtool.api`), one of them for a
fleet."""

_TARGET = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_]\w*$")
_NAME = re.compile(r"^[a-z][a-z0-9_-]*$")


class PluginError(InputError):
    """A mission that cannot be found or loaded (exit 2)."""


@dataclass(frozen=True, slots=True)
class MissionRef:
    """Which mission flew: its name, where its class lives (``module:Class``) and the version
    of the package that holds it."""

    name: str
    target: str
    version: str


@dataclass(frozen=True, slots=True)
class MissionInfo:
    """A mission ``uavtool missions`` lists."""

    name: str
    target: str
    origin: str
    """``uavtool`` for a built-in one, else the registering package."""
    summary: str
    """The first line of the class's docstring ("" when it cannot be loaded)."""
    error: str = ""
    """Why it cannot be loaded ("" when it can)."""


def registered() -> dict[str, tuple[str, str]]:
    """Every mission name → (``module:Class``, origin): built-in first, then installed
    packages' (a package cannot take a built-in name)."""
    import importlib.metadata  # noqa: PLC0415 - ~25 ms: not for a built-in mission's flight

    found = {name: (target, "uavtool") for name, target in BUILTIN.items()}
    for ep in importlib.metadata.entry_points(group=GROUP):
        if ep.name not in found:
            origin = ep.dist.name if ep.dist is not None else "?"
            found[ep.name] = (ep.value, origin)
    return found


def resolve(spec: str) -> tuple[type[FlightMission], MissionRef]:
    """The mission class that ``spec`` names (a registered name or ``module:Class``), and how
    a recording refers to it. Raises PluginError (one line, naming ``spec``)."""
    spec = spec.strip()
    known = {spec: (BUILTIN[spec], "uavtool")} if spec in BUILTIN else registered()
    if spec in known:  # a built-in name is never a package's (see `registered`)
        name, target = spec, known[spec][0]
    elif _TARGET.match(spec):
        target = spec
        name = next((n for n, (t, _) in known.items() if t == spec), spec)
    else:
        names = ", ".join(sorted(known))
        raise PluginError(
            f"--mission {spec!r}: no such mission; registered: {names} "
            "(or give module:Class; `uavtool missions` lists them)"
        )
    cls = load(target, what=f"--mission {spec!r}")
    return cls, MissionRef(name, target, _version_of(target))


def code_dir() -> str:
    """Where ``module:name`` given on the command line is looked for besides the installed
    packages: the current folder, as uvicorn and gunicorn do (put there on ``sys.path``)."""
    here = str(Path.cwd())
    if here not in sys.path:
        sys.path.insert(0, here)
    return here


def load(target: str, *, what: str) -> type[FlightMission]:
    """Import ``module:Class`` and check it is a mission; PluginError otherwise."""
    code_dir()
    module_name, _, attr = target.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise PluginError(
            f"{what}: cannot import {module_name}: {exc}; is its package installed in this "
            "environment?"
        ) from None
    except Exception as exc:
        raise PluginError(
            f"{what}: importing {module_name} failed: {type(exc).__name__}: {exc}"
        ) from None
    cls = getattr(module, attr, None)
    if cls is None:
        raise PluginError(f"{what}: {module_name} has no {attr}")
    if not (isinstance(cls, type) and issubclass(cls, FlightMission)):
        raise PluginError(f"{what}: {target} is not a mission (subclass uavtool.api.FlightMission)")
    check_params_type(cls, what=what)
    return cls


def for_recording(
    ref: MissionRef, *, source: str, override: str | None = None
) -> tuple[type[FlightMission], MissionRef]:
    """The class of the mission a recording flew. A recording is untrusted: it may name only
    a mission registered here (by name and class alike), never make uavtool import a module
    of its choosing; ``override`` (``--mission`` on the command line) names one explicitly."""
    if override is not None:
        return resolve(override)
    known = {ref.name: (BUILTIN[ref.name], "uavtool")} if ref.name in BUILTIN else registered()
    if ref.name in known and known[ref.name][0] == ref.target:
        return load(ref.target, what=f"{source}: mission {ref.name!r}"), ref
    hint = (
        f"install the package that provides it, or pass --mission {ref.target} to load it"
        if _TARGET.match(ref.target)
        else "the recording names it in an unknown form"
    )
    raise PluginError(
        f"{source}: flown by mission {ref.name[:40]!r} ({ref.target[:80]}), which is not "
        f"registered here: {hint}"
    )


def flight_params(cls: type[FlightMission], params: Any) -> FlightParams:
    """The :class:`FlightParams` group of a mission's parameters."""
    group: FlightParams = getattr(params, cls.flight_group)
    return group


def check_params_type(cls: type[FlightMission], *, what: str) -> None:
    """A mission's ``params_type`` must build with no arguments and hold a FlightParams group
    named by ``flight_group``."""
    try:
        params = cls.params_type()
    except Exception as exc:
        raise PluginError(f"{what}: {cls.__name__}.params_type() failed: {exc}") from None
    if not isinstance(getattr(params, cls.flight_group, None), FlightParams):
        raise PluginError(
            f"{what}: {cls.__name__}.params_type has no FlightParams group {cls.flight_group!r} "
            "(set the class's flight_group)"
        )


def ref_of(cls: type[FlightMission]) -> MissionRef:
    """How a recording names a mission class."""
    target = f"{cls.__module__}:{cls.__qualname__}"
    known = {t: n for n, (t, _) in registered().items()}
    name = known.get(target) or cls.name or target
    return MissionRef(name, target, _version_of(target))


def available() -> list[MissionInfo]:
    """Every registered mission, loaded to read its summary (a broken one says why)."""
    out = []
    for name, (target, origin) in registered().items():
        try:
            cls = load(target, what=f"mission {name!r}")
        except PluginError as exc:
            out.append(MissionInfo(name, target, origin, "", str(exc)))
            continue
        doc = (cls.__doc__ or "").strip().splitlines()
        out.append(MissionInfo(name, target, origin, doc[0] if doc else ""))
    return out


def _version_of(target: str) -> str:
    """The version of the installed distribution that holds ``target``'s module."""
    top = target.split(":", 1)[0].split(".", 1)[0]
    if top == "uavtool":
        return __version__
    import importlib.metadata  # noqa: PLC0415

    dists = importlib.metadata.packages_distributions().get(top, [])
    for dist in dists:
        try:
            return importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
    return ""


class MissionCodeError(FailureError):
    """The mission's own code raised (a bug in it): the run stops (a flight sends the vehicle
    home)."""


def create_mission(cls: type[FlightMission], params: Any, inputs: MissionInputs) -> FlightMission:
    """The mission object; a plug-in's own failure is a one-line error naming it. A fleet
    mission flown by one vehicle is a fleet of one."""
    if issubclass(cls, FleetMember):
        return create_fleet(cls, params, inputs, ((0.0, 0.0),))[0]
    return _starting(cls, lambda: cls(params, inputs))


def create_fleet(
    cls: type[FleetMember],
    params: Any,
    inputs: MissionInputs,
    homes_en_m: tuple[tuple[float, float], ...],
) -> list[FleetMember]:
    """A fleet mission's members, one per home (the fleet's frame); a plug-in's own failure
    is a one-line error naming it."""
    return _starting(cls, lambda: cls.fleet(params, inputs, homes_en_m))


def _starting(cls: type[FlightMission], make: Callable[[], T]) -> T:
    """``make()``; a plug-in's own exception becomes a PluginError naming ``cls``."""
    try:
        return make()
    except InputError:
        raise
    except Exception as exc:
        raise PluginError(
            f"mission {cls.__name__} could not start: {type(exc).__name__}: {exc}"
        ) from None


def guarded(call: Callable[..., list[Output]], *args: Observation) -> list[Output]:
    """``call(*args)`` (a mission's start or step); an exception from the mission's code
    becomes one line naming it and where it was raised."""
    try:
        return call(*args)
    except UavtoolError:
        raise
    except Exception as exc:
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        where = f"{Path(frame.filename).name}:{frame.lineno}"
        raise MissionCodeError(
            f"the mission raised {type(exc).__name__}: {exc} (at {where})"
        ) from exc


def mission_params(cls: type[FlightMission], data: Any, *, source: str) -> Any:
    """``cls``'s parameters from their JSON form (a recording's, a spec's)."""
    return from_dict(data, cls.params_type, source=source)
