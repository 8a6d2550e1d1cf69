"""A spec expanded into flights: scenes × cases × grid × random draws, each a
:class:`FlightSpec` with a stable index and a key that changes whenever any of its inputs
does."""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import random
import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from uavtool.mission.fleet import FleetMember
from uavtool.plugins import resolve
from uavtool.sweep import dimensions
from uavtool.sweep.errors import SpecError
from uavtool.sweep.scenes import scene_label
from uavtool.sweep.spec import SceneSource, SweepSpec
from uavtool.sweep.values import Distribution, Law
from uavtool.terminal import counted

_DEFAULTS: dict[str, Any] = {
    "seed": 0,
    "wind_speed_ms": 0.0,
    "wind_from_deg": 0.0,
    "noise": False,
    "home_heading_deg": None,  # the scene's own
    "link_outages": (),
    "vehicles": 1,
}


@dataclass(frozen=True, slots=True)
class FlightSpec:
    """One flight of a sweep. ``scene.seeds`` holds just this flight's generator seed."""

    index: int
    scene: SceneSource
    inputs: tuple[tuple[str, Any], ...]
    """The dimensions the sweep sets for this flight, in spec order."""
    mission: str = "search"
    """The mission it flies."""

    @property
    def scene_seed(self) -> int | None:
        return self.scene.seeds[0] if self.scene.seeds else None

    @property
    def label(self) -> str:
        return scene_label(self.scene, self.scene_seed)

    @property
    def key(self) -> str:
        """8 hex digits of a hash of everything that shapes the flight (not its index)."""
        shaped = [self.label, self.scene.digest, self.scene.options, self.inputs]
        if self.mission != "search":  # the built-in mission's flights keep their keys
            shaped.append(self.mission)
        text = json.dumps(shaped, sort_keys=True, default=list)
        return hashlib.sha256(text.encode()).hexdigest()[:8]

    @property
    def stem(self) -> str:
        """File name stem of its recording and row: ``000012-hard-17-1a2b3c4d``."""
        return f"{self.index:06d}-{re.sub(r'[^A-Za-z0-9._]+', '-', self.label)}-{self.key}"

    def value(self, key: str) -> Any:
        return dict(self.inputs).get(key, _DEFAULTS.get(key))

    def link_outages_s(self) -> tuple[tuple[float, float], ...]:
        outages = tuple(tuple(o) for o in self.value("link_outages"))
        duration_s = float(self.value("outage_duration_s") or 0.0)
        if duration_s > 0:
            outages += ((float(self.value("outage_start_s") or 0.0), duration_s),)
        return outages

    def settings(self) -> dict[str, str]:
        """Mission parameters as ``uavtool fly --set`` takes them."""
        n = len(dimensions.SET_PREFIX)
        return {
            k[n:]: dimensions.setting_text(v)
            for k, v in self.inputs
            if k.startswith(dimensions.SET_PREFIX)
        }

    def vehicle_params(self) -> tuple[tuple[str, float], ...]:
        n = len(dimensions.PARAM_PREFIX)
        return tuple(
            (k[n:], float(v)) for k, v in self.inputs if k.startswith(dimensions.PARAM_PREFIX)
        )


def dimension_keys(spec: SweepSpec) -> tuple[str, ...]:
    """The table's input columns: the built-in ones, then the sweep's own set./param. keys."""
    named = [k for case in spec.cases for k, _ in case]
    named += [k for k, _ in (*spec.grid, *spec.random)]
    extra = [k for k in dict.fromkeys(named) if k not in dimensions.BUILTIN_KEYS]
    keys = list(_DEFAULTS)
    keys += [k for k in ("outage_start_s", "outage_duration_s") if _uses(spec, k)]
    return (*keys, *extra)


def _uses(spec: SweepSpec, key: str) -> bool:
    return any(k == key for k, _ in (*spec.grid, *spec.random, *itertools.chain(*spec.cases)))


MAX_FLIGHTS = 100_000
"""Flights one sweep may plan: each is a recording and a row, and the plan is held in memory
(1000 x 1000 x 1000 grid values asked for 3.5 GB before failing)."""


def flight_count(spec: SweepSpec) -> int:
    """How many flights ``spec`` plans, counted without planning them."""
    return math.prod(_factors(spec).values())


def _factors(spec: SweepSpec) -> dict[str, int]:
    return {
        "scene": sum(len(source.seeds) or 1 for source in spec.scenes),
        "case": len(spec.cases or ((),)),
        **{f"{key} value": len(values) for key, values in spec.grid},
        "draw": max(spec.draws, 1),
    }


def plan_flights(spec: SweepSpec) -> list[FlightSpec]:
    """Every flight, in a fixed order: scene, case, grid combination, draw. Raises
    SpecError when a random draw is not a valid value of its dimension, or when the spec
    plans more than ``MAX_FLIGHTS`` (before planning any)."""
    count = flight_count(spec)
    if count > MAX_FLIGHTS:
        sizes = " x ".join(counted(n, what) for what, n in _factors(spec).items())
        raise SpecError(
            spec.source,
            "",
            f"{count:,} flights ({sizes}): at most {MAX_FLIGHTS:,} in one sweep; use fewer "
            "grid values or draws, or split it into several sweeps",
        )
    return list(_flights(spec))


def _flights(spec: SweepSpec) -> Iterator[FlightSpec]:
    keys = [k for k, _ in spec.grid]
    checked: dict[tuple[str, str], Any] = {}
    mission = resolve(spec.mission)[0]
    params_type = mission.params_type  # once: the draws check against it
    fleets = issubclass(mission, FleetMember)
    index = 0
    for source in spec.scenes:
        for seed in source.seeds or (None,):
            one = dataclasses.replace(source, seeds=() if seed is None else (seed,))
            label = scene_label(source, seed)
            combos = itertools.product(spec.cases or ((),), *(v for _, v in spec.grid))
            for g, (case, *combo) in enumerate(combos):
                for d in range(max(spec.draws, 1)):
                    inputs = [*case, *zip(keys, combo, strict=True)]
                    if spec.random:
                        rng = random.Random(f"{spec.rng_seed}|{label}|{g}|{d}")
                        inputs += [
                            (k, _draw(k, law, rng, checked, spec, params_type))
                            for k, law in spec.random
                        ]
                    vehicles = dict(inputs).get("vehicles", 1)
                    if vehicles > 1 and not fleets:
                        raise SpecError(
                            spec.source,
                            "vehicles",
                            f"{vehicles} vehicles: the mission {spec.mission!r} flies one; a "
                            'fleet flies a fleet mission (sweep.mission = "fleet-search")',
                        )
                    yield FlightSpec(index, one, tuple(inputs), spec.mission)
                    index += 1


def _draw(
    key: str,
    law: Distribution,
    rng: random.Random,
    checked: dict[tuple[str, str], Any],
    spec: SweepSpec,
    params_type: type,
) -> Any:
    value = law.draw(rng)
    if law.law is Law.UNIFORM and key.startswith(dimensions.SET_PREFIX):
        return value  # both bounds were checked with the spec
    memo = (key, repr(value))
    if memo not in checked:
        try:
            checked[memo] = dimensions.check(key, value, params_type)
        except (KeyError, ValueError) as exc:
            raise SpecError(spec.source, f"random.{key}", f"drew {value!r}: {exc}") from None
    return checked[memo]
