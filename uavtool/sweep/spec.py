"""The sweep spec: a small TOML file (plus ``--set KEY=VALUE``) read into a checked
:class:`SweepSpec`. Every problem is a :class:`SpecError` naming the key path.

Example (paths are relative to the spec file)::

    [sweep]
    out = "sweeps/wind"           # default: sweeps/<spec name>, relative to the current folder
    format = "parquet"            # or "csv"
    retries = 2                   # re-runs of a task that raised outside the flight
    timeout_s = 900               # vehicle seconds a flight may last (default: no limit)
    mission = "search"            # which mission flies (uavtool missions): set.* are its parameters

    [scenes]
    builtin = ["paper", "blocked-front"]
    files = ["yard.yaml"]
    hard = { seeds = { first = 1, count = 100 }, max_buildings = 6 }   # uavtool.world.hard
    random = { seeds = [1, 2], buildings = 5 }                          # uavtool scene random

    [grid]                        # every combination, for every scene
    seed = [0, 1]
    wind_speed_ms = { from = 0, to = 8, step = 4 }
    "set.recognize.threshold" = [0.7, 0.75]

    [random]                      # DRAWS seeded draws for every scene and grid point
    draws = 10
    rng_seed = 7
    wind_from_deg = { uniform = [0, 360] }

    [[cases]]                     # optional: inputs that go together (each case crosses
    seed = 11                     # the scenes, the grid and the draws)
    wind_from_deg = 90
    [[cases]]
    seed = 12
    "set.mission.max_looks" = 1
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import re
import tomllib
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, fields
from enum import Enum
from pathlib import Path
from typing import Any

from uavtool.checks import SEED_RANGE, shown
from uavtool.errors import UavtoolError
from uavtool.plugins import resolve
from uavtool.sweep import dimensions
from uavtool.sweep.errors import SpecError
from uavtool.sweep.values import Distribution, distribution, value_list

MAX_SPEC_BYTES = 1 << 20
"""A spec is a few hundred bytes; this bounds what is read and parsed."""
_TOP = ("sweep", "scenes", "grid", "random", "cases")
_SWEEP_KEYS = ("out", "format", "retries", "timeout_s", "mission")
_SCENE_KEYS = ("builtin", "files", "hard", "random")
_RANDOM_SCENE_OPTIONS = ("buildings", "margin_m")


class SceneKind(Enum):
    BUILTIN = "builtin"
    FILE = "file"
    RANDOM = "random"
    HARD = "hard"


class TableFormat(Enum):
    PARQUET = "parquet"
    CSV = "csv"


@dataclass(frozen=True, slots=True)
class SceneSource:
    """One ``[scenes]`` entry: a built-in scene, a file, or a generator with its seeds."""

    kind: SceneKind
    name: str = ""
    """The built-in name, or the file as the spec writes it."""
    path: Path | None = None
    digest: str = ""
    """First 12 hex digits of the file's SHA-256: a changed file is a new flight."""
    seeds: tuple[int, ...] = ()
    options: tuple[tuple[str, Any], ...] = ()


@dataclass(frozen=True, slots=True)
class SweepSpec:
    source: str
    scenes: tuple[SceneSource, ...]
    grid: tuple[tuple[str, tuple[Any, ...]], ...]
    """Each dimension with its values, in spec order; flights take every combination."""
    random: tuple[tuple[str, Distribution], ...]
    draws: int
    rng_seed: int
    out: Path
    table_format: TableFormat
    retries: int
    timeout_s: float | None = None
    """Vehicle seconds a flight may last before it is stopped (a row with its error)."""
    cases: tuple[tuple[tuple[str, Any], ...], ...] = ()
    """Sets of inputs that go together; flights take every case (none: one empty case)."""
    mission: str = "search"
    """The mission every flight flies (a registered name or ``module:Class``)."""
    text: str = ""
    """The spec file as read, with its overrides appended as comments (kept with the results)."""


def load_spec(path: Path, overrides: Sequence[str] = ()) -> SweepSpec:
    """Read and check the spec at ``path`` with ``KEY.PATH=VALUE`` overrides (VALUE in TOML
    syntax, or a bare word). Raises SpecError."""
    source = str(path)
    try:
        with path.open("rb") as file:
            raw = file.read(MAX_SPEC_BYTES + 1)
    except OSError as exc:
        raise SpecError(source, "", f"cannot read: {exc.strerror}") from None
    if len(raw) > MAX_SPEC_BYTES:
        raise SpecError(source, "", f"larger than {MAX_SPEC_BYTES // 1024} KiB: not a sweep spec")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise SpecError(source, "", f"not UTF-8 text (byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(source, "", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise SpecError(source, "", "not valid TOML: nested too deeply") from None
    text = raw.decode("utf-8")
    for override in overrides:
        _apply_override(data, override, source)
    spec = parse_spec(data, source=source, base=path.parent, default_out=Path("sweeps") / path.stem)
    notes = "".join(f"# --set {o}\n" for o in overrides)
    return dataclasses.replace(spec, text=text + ("\n" + notes if notes else ""))


def parse_spec(data: Mapping[str, Any], *, source: str, base: Path, default_out: Path) -> SweepSpec:
    """A checked spec from TOML data; relative paths are taken from ``base``."""
    _known(data, _TOP, "", source)
    sweep = _table(data, "sweep", source)
    _known(sweep, _SWEEP_KEYS, "sweep.", source)
    out = sweep.get("out")
    if out is not None and not isinstance(out, str):
        raise SpecError(source, "sweep.out", f"expected a folder path, got {shown(out)}")
    fmt = sweep.get("format", "parquet")
    if not isinstance(fmt, str) or fmt not in {f.value for f in TableFormat}:
        raise SpecError(source, "sweep.format", f"expected 'parquet' or 'csv', got {shown(fmt)}")
    retries = sweep.get("retries", 2)
    if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= 10:
        raise SpecError(source, "sweep.retries", f"expected 0..10, got {shown(retries)}")
    mission = sweep.get("mission", "search")
    if not isinstance(mission, str):
        raise SpecError(source, "sweep.mission", f"expected a mission's name, got {shown(mission)}")
    try:
        params_type = resolve(mission)[0].params_type
    except UavtoolError as exc:
        raise SpecError(source, "sweep.mission", str(exc)) from None
    check = functools.partial(_checked, params_type=params_type)
    grid = tuple(_grid(_table(data, "grid", source), source, check))
    draws, rng_seed, random = _random(_table(data, "random", source), source, check)
    taken = {k for k, _ in grid} & {k for k, _ in random}
    if taken:
        raise SpecError(source, f"random.{min(taken)}", "already a grid dimension")
    taken = {k for k, _ in (*grid, *random)}
    cases = tuple(_cases(data.get("cases", []), taken, source, check))
    return SweepSpec(
        source=source,
        scenes=tuple(_scenes(data.get("scenes", {"builtin": ["paper"]}), base, source)),
        grid=grid,
        random=random,
        draws=draws,
        rng_seed=rng_seed,
        out=base / out if out is not None else default_out,
        table_format=TableFormat(fmt),
        retries=retries,
        timeout_s=_timeout(sweep.get("timeout_s"), source),
        cases=cases,
        mission=mission,
    )


def _timeout(value: Any, source: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise SpecError(
            source, "sweep.timeout_s", f"expected vehicle seconds > 0, got {shown(value)}"
        )
    return float(value)


Check = Callable[[str, Any, str, str], Any]
"""``_checked`` for the sweep's mission: (key, value, where, source) → the value."""


def _cases(
    value: Any, taken: set[str], source: str, check: Check
) -> Iterator[tuple[tuple[str, Any], ...]]:
    if not isinstance(value, list) or not all(isinstance(case, dict) for case in value):
        raise SpecError(source, "cases", "expected an array of tables ([[cases]])")
    for i, case in enumerate(value):
        inputs = []
        for key, raw in _flatten(case):
            where = f"cases[{i}].{key}"
            if key in taken:
                raise SpecError(source, where, "already a grid or random dimension")
            inputs.append((key, check(key, raw, where, source)))
        yield tuple(inputs)


def _apply_override(data: dict[str, Any], text: str, source: str) -> None:
    key, sep, raw = text.partition("=")
    if not sep or not key.strip():
        raise SpecError(source, "", f"--set {shown(text)}: expected KEY.PATH=VALUE")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except (tomllib.TOMLDecodeError, RecursionError):
        value = raw.strip()  # a bare word: a name or a path
    node = data
    parts = key.strip().split(".")
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise SpecError(source, key, f"--set: {shown(part)} is not a table")
        node = child
    node[parts[-1]] = value


def _known(table: Mapping[str, Any], keys: Sequence[str], prefix: str, source: str) -> None:
    for key in table:
        if key not in keys:
            raise SpecError(
                source, f"{prefix}{key}", f"unknown key; expected one of {', '.join(keys)}"
            )


def _table(data: Mapping[str, Any], key: str, source: str) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise SpecError(source, key, f"expected a table, got {shown(value)}")
    return value


def _flatten(table: Mapping[str, Any], prefix: str = "") -> Iterator[tuple[str, Any]]:
    """Dimension keys with their raw values: ``set.GROUP.NAME`` and ``param.NAME`` may be
    written as nested tables or as quoted dotted keys."""
    for key, value in table.items():
        path = f"{prefix}{key}"
        head = path.split(".", maxsplit=1)[0]
        depth = 3 if head == "set" else 2 if head == "param" else 1
        if isinstance(value, dict) and len(path.split(".")) < depth:
            yield from _flatten(value, f"{path}.")
        else:
            yield path, value


def _checked(key: str, value: Any, where: str, source: str, *, params_type: type) -> Any:
    try:
        return dimensions.check(key, value, params_type)
    except KeyError as exc:
        # An unknown key is wrong in all its values: name the key, not one value.
        raise SpecError(source, re.sub(r"\[\d+\]$", "", where), str(exc.args[0])) from None
    except ValueError as exc:
        raise SpecError(source, where, str(exc)) from None


def _grid(
    table: Mapping[str, Any], source: str, check: Check
) -> Iterator[tuple[str, tuple[Any, ...]]]:
    for key, raw in _flatten(table):
        try:
            values = value_list(raw, list_valued=key == "link_outages")
        except ValueError as exc:
            raise SpecError(source, f"grid.{key}", str(exc)) from None
        yield key, tuple(check(key, v, f"grid.{key}[{i}]", source) for i, v in enumerate(values))


def _random(
    table: dict[str, Any], source: str, check: Check
) -> tuple[int, int, tuple[tuple[str, Distribution], ...]]:
    table = dict(table)
    draws = table.pop("draws", None)
    rng_seed = table.pop("rng_seed", 0)
    if isinstance(rng_seed, bool) or not isinstance(rng_seed, int) or rng_seed not in SEED_RANGE:
        raise SpecError(
            source,
            "random.rng_seed",
            f"expected a whole number {SEED_RANGE}, got {shown(rng_seed)}",
        )
    laws = []
    for key, raw in _flatten(table):
        try:
            law = distribution(raw)
        except ValueError as exc:
            raise SpecError(source, f"random.{key}", str(exc)) from None
        # Every choice, or both bounds (a mission parameter valid at both ends of a range
        # is valid between them: draws of it are not checked again one by one).
        for i, value in enumerate(law.support()):
            check(key, value, f"random.{key}[{i}]", source)
        laws.append((key, law))
    if draws is None:
        draws = 1 if laws else 0
    if isinstance(draws, bool) or not isinstance(draws, int) or not 0 <= draws <= 1_000_000:
        raise SpecError(source, "random.draws", f"expected 0..1000000, got {shown(draws)}")
    if laws and draws == 0:
        raise SpecError(source, "random.draws", "0 draws leave the random dimensions unused")
    return draws, rng_seed, tuple(laws)


def _entries(value: Any) -> list[Any]:
    return value if isinstance(value, list) else [value]


def _scenes(value: Any, base: Path, source: str) -> Iterator[SceneSource]:
    if not isinstance(value, dict):
        raise SpecError(source, "scenes", f"expected a table, got {shown(value)}")
    _known(value, _SCENE_KEYS, "scenes.", source)
    from uavtool.world import builtin_scene_names, load_scene  # noqa: PLC0415

    names = builtin_scene_names()
    for i, name in enumerate(_entries(value.get("builtin", []))):
        if name not in names:
            where = f"scenes.builtin[{i}]"
            raise SpecError(
                source, where, f"no built-in scene {shown(name)}; one of {', '.join(names)}"
            )
        yield SceneSource(SceneKind.BUILTIN, name=name)
    for i, name in enumerate(_entries(value.get("files", []))):
        where = f"scenes.files[{i}]"
        if not isinstance(name, str):
            raise SpecError(source, where, f"expected a file path, got {shown(name)}")
        path = base / name
        try:
            load_scene(path)
            digest = hashlib.sha256(path.read_bytes()).hexdigest()[:12]
        except (UavtoolError, OSError) as exc:
            raise SpecError(source, where, str(exc)) from None
        yield SceneSource(SceneKind.FILE, name=name, path=path.resolve(), digest=digest)
    for kind in (SceneKind.HARD, SceneKind.RANDOM):
        for i, entry in enumerate(_entries(value.get(kind.value, []))):
            yield _generated(kind, entry, f"scenes.{kind.value}[{i}]", source)


def _generated(kind: SceneKind, entry: Any, where: str, source: str) -> SceneSource:
    if not isinstance(entry, dict) or "seeds" not in entry:
        raise SpecError(source, where, "expected a table with seeds and generator options")
    options = {k: v for k, v in entry.items() if k != "seeds"}
    try:
        seeds = value_list(entry["seeds"])
    except ValueError as exc:
        raise SpecError(source, f"{where}.seeds", str(exc)) from None
    for i, seed in enumerate(seeds):
        if isinstance(seed, bool) or not isinstance(seed, int) or seed not in SEED_RANGE:
            raise SpecError(
                source,
                f"{where}.seeds[{i}]",
                f"expected a whole number {SEED_RANGE}, got {shown(seed)}",
            )
    if kind is SceneKind.HARD:
        from uavtool.world.hard import HardOptions  # noqa: PLC0415

        allowed = tuple(f.name for f in fields(HardOptions))
    else:
        allowed = _RANDOM_SCENE_OPTIONS
    _known(options, allowed, f"{where}.", source)
    probe = SceneSource(kind, seeds=(seeds[0],), options=tuple(sorted(options.items())))
    try:
        from uavtool.sweep.scenes import load_source_scene  # noqa: PLC0415

        load_source_scene(probe, seeds[0])
    except (UavtoolError, TypeError) as exc:
        raise SpecError(source, where, str(exc)) from None
    return SceneSource(kind, seeds=tuple(seeds), options=probe.options)
