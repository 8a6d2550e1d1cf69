"""Scenes: buildings made of extruded blocks around home, plus ground, sky and sun.

A scene file (YAML, TOML or JSON) holds the same data as :func:`scene_to_dict`::

    version: 1
    name: paper
    origin: {lat_deg: 50.06, lon_deg: 19.94, alt_amsl_m: 220.0, heading_deg: 0.0}
    ground: {color: [128, 128, 128]}   # areas and a texture too: see uavtool.world.ground
    sky: {color: [205, 218, 232]}
    lighting: {sun_azimuth_deg: 150.0, sun_elevation_deg: 60.0, ambient: 0.55}
    target: red
    buildings:
      - name: red
        color: [210, 40, 40]
        blocks:
          - {footprint: [[0, 0], [4, 0], [4, 3], [0, 3]], base_m: 0.0, top_m: 6.0}

Footprints are metres east/north of home; they are stored counter-clockwise (a clockwise
footprint is reversed on load). A building is the union of its blocks, so stacked blocks
make stepped towers and a block resting on two others makes a through-hole.
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, NoReturn

import shapely
import yaml

from uavtool.geo import GeoPoint
from uavtool.world import limits
from uavtool.world.errors import SceneError
from uavtool.world.ground import GroundArea, GroundTexture, ground_to_dict, read_ground
from uavtool.world.polygon import normalise_ring, signed_area
from uavtool.world.scene_file import KeyPath, format_path, parse_text

FORMAT_VERSION = 1
_MIN_AREA_M2 = 1e-4
_OVERLAP_M2 = 1e-6

RGB = tuple[int, int, int]

DEFAULT_GROUND_RGB: RGB = (128, 128, 128)
DEFAULT_SKY_RGB: RGB = (205, 218, 232)


@dataclass(frozen=True, slots=True)
class Block:
    """A prism: a simple counter-clockwise footprint extruded from ``base_m`` up to ``top_m``."""

    footprint_enu_m: tuple[tuple[float, float], ...]
    base_m: float
    top_m: float


@dataclass(frozen=True, slots=True)
class Building:
    """A named, single-coloured union of blocks."""

    name: str
    color_rgb: RGB
    blocks: tuple[Block, ...]


@dataclass(frozen=True, slots=True)
class Lighting:
    """A directional sun (azimuth clockwise from north) plus an ambient share in [0, 1]."""

    sun_azimuth_deg: float = 150.0
    sun_elevation_deg: float = 60.0
    ambient: float = 0.55


@dataclass(frozen=True, slots=True)
class Scene:
    """Everything the renderer and the evaluation need; buildings in ENU metres around home."""

    name: str
    home: GeoPoint
    home_heading_deg: float
    buildings: tuple[Building, ...]
    target: str
    ground_rgb: RGB = DEFAULT_GROUND_RGB
    sky_rgb: RGB = DEFAULT_SKY_RGB
    lighting: Lighting = Lighting()
    description: str = ""
    ground_areas: tuple[GroundArea, ...] = ()  # drawn in order over the ground colour
    ground_texture: GroundTexture | None = None

    def building(self, name: str) -> Building:
        """The building called ``name``; raises SceneError if there is none."""
        for b in self.buildings:
            if b.name == name:
                return b
        raise SceneError(f"scene {self.name!r} has no building {name!r}")

    @property
    def target_building(self) -> Building:
        return self.building(self.target)


# --------------------------------------------------------------------------- to dict


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """Plain data (str, int, float, list, dict) that :func:`scene_from_dict` reads back."""
    return {
        "version": FORMAT_VERSION,
        "name": scene.name,
        "description": scene.description,
        "origin": {
            "lat_deg": scene.home.lat_deg,
            "lon_deg": scene.home.lon_deg,
            "alt_amsl_m": scene.home.alt_amsl_m,
            "heading_deg": scene.home_heading_deg,
        },
        "ground": ground_to_dict(scene.ground_rgb, scene.ground_areas, scene.ground_texture),
        "sky": {"color": list(scene.sky_rgb)},
        "lighting": {
            "sun_azimuth_deg": scene.lighting.sun_azimuth_deg,
            "sun_elevation_deg": scene.lighting.sun_elevation_deg,
            "ambient": scene.lighting.ambient,
        },
        "target": scene.target,
        "buildings": [
            {
                "name": b.name,
                "color": list(b.color_rgb),
                "blocks": [
                    {
                        "footprint": [[x, y] for x, y in blk.footprint_enu_m],
                        "base_m": blk.base_m,
                        "top_m": blk.top_m,
                    }
                    for blk in b.blocks
                ],
            }
            for b in scene.buildings
        ],
    }


def dump_scene(scene: Scene, *, suffix: str = ".yaml") -> str:
    """The scene as file text: YAML, or JSON for ``suffix == ".json"``."""
    data = scene_to_dict(scene)
    if suffix == ".json":
        return json.dumps(data, indent=2) + "\n"
    text: str = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100)
    return text


# --------------------------------------------------------------------------- from dict


class _Reader:
    """Type-checked access to parsed data; every failure names the source, line and key path."""

    def __init__(self, source: str, lines: Mapping[KeyPath, int]) -> None:
        self.source = source
        self.lines = lines
        self.vertices = 0  # footprint and area vertices read so far, against MAX_SCENE_VERTICES

    def fail(self, path: KeyPath, message: str) -> NoReturn:
        line = None
        for n in range(len(path), -1, -1):
            line = self.lines.get(path[:n])
            if line is not None:
                break
        where = f"{self.source}:{line}" if line is not None else self.source
        key = format_path(path)
        raise SceneError(f"{where}: {key}: {message}" if key else f"{where}: {message}")

    def mapping(
        self, value: object, path: KeyPath, required: Sequence[str], optional: Sequence[str] = ()
    ) -> dict[str, Any]:
        if not isinstance(value, Mapping):
            self.fail(path, f"expected a mapping, got {_kind(value)}")
        allowed = [*required, *optional]
        for key in value:
            if key not in allowed:
                if not _plain_key(key):  # not a scene, maybe a secret: never echo its text
                    self.fail(
                        path,
                        f"a key that is not a scene key (is this a scene file?); "
                        f"allowed: {', '.join(allowed)}",
                    )
                hint = difflib.get_close_matches(str(key), allowed, n=1)
                extra = f" (did you mean {hint[0]!r}?)" if hint else ""
                self.fail((*path, str(key)), f"unknown key{extra}; allowed: {', '.join(allowed)}")
        for key in required:
            if key not in value:
                self.fail(path, f"missing key {key!r}")
        return dict(value)

    def number(self, value: object, path: KeyPath) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(path, f"expected a number, got {_kind(value)}")
        try:
            out = float(value)
        except OverflowError:
            out = math.inf
        if not math.isfinite(out):
            self.fail(path, f"expected a finite number, got {_shown(value)}")
        return out

    def text(self, value: object, path: KeyPath) -> str:
        if not isinstance(value, str):
            self.fail(path, f"expected a string, got {_kind(value)}")
        if len(value) > limits.MAX_TEXT_CHARS:
            self.fail(path, f"longer than {limits.MAX_TEXT_CHARS} characters")
        return value

    def sequence(self, value: object, path: KeyPath, *, most: int | None = None) -> list[Any]:
        if not isinstance(value, list | tuple):
            self.fail(path, f"expected a list, got {_kind(value)}")
        if most is not None and len(value) > most:
            self.fail(path, f"at most {most} items allowed, got {len(value)}")
        return list(value)

    def color(self, value: object, path: KeyPath) -> RGB:
        items = self.sequence(value, path)
        ok = len(items) == 3 and all(
            isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255 for c in items
        )
        if not ok:
            self.fail(path, f"expected [r, g, b] with integers 0-255, got {_shown(value)}")
        return (items[0], items[1], items[2])

    def whole(self, value: object, path: KeyPath, lo: int, hi: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            self.fail(path, f"expected a whole number {lo}..{hi}, got {_shown(value)}")
        return value

    def ring(self, value: object, path: KeyPath, *, what: str) -> tuple[tuple[float, float], ...]:
        """A simple polygon of [east_m, north_m] points (a footprint, a ground area),
        counter-clockwise; every point counts against MAX_SCENE_VERTICES."""
        raw = self.sequence(value, path, most=limits.MAX_FOOTPRINT_VERTICES)
        self.vertices += len(raw)
        if self.vertices > limits.MAX_SCENE_VERTICES:
            self.fail(
                path,
                f"the scene has more than {limits.MAX_SCENE_VERTICES} footprint vertices "
                "(ground areas' included)",
            )
        pts: list[tuple[float, float]] = []
        for k, p in enumerate(raw):
            xy = self.sequence(p, (*path, k))
            if len(xy) != 2:
                self.fail((*path, k), f"expected [east_m, north_m], got {_shown(p)}")
            x_m, y_m = self.number(xy[0], (*path, k, 0)), self.number(xy[1], (*path, k, 1))
            if max(abs(x_m), abs(y_m)) > limits.MAX_EXTENT_M:
                self.fail((*path, k), f"more than {limits.MAX_EXTENT_M:g} m from home")
            pts.append((x_m, y_m))
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts.pop()
        if len(pts) < 3:
            self.fail(path, f"a {what} needs at least 3 vertices, got {len(pts)}")
        for k in range(len(pts)):
            if pts[k] == pts[k - 1]:
                self.fail((*path, k), "repeated vertex")
        if abs(signed_area(pts)) < _MIN_AREA_M2:
            self.fail(path, "polygon has zero area")
        if not shapely.LinearRing(pts).is_simple:
            self.fail(path, "self-intersecting polygon")
        return normalise_ring(pts)


def _plain_key(key: object) -> bool:
    """A key worth naming in an error: a short word such as ``colour`` or ``top-m``, not a line
    of some other file (``root:$6$…`` from /etc/shadow read as YAML)."""
    if not isinstance(key, str):  # 1: or 0xfff…: (an integer too long to turn into text)
        return False
    text = key
    return len(text) <= 32 and text.replace("-", "_").replace(" ", "_").isidentifier()


def _kind(value: object) -> str:
    return "nothing" if value is None else type(value).__name__


def _clip(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _shown(value: object) -> str:
    """``value`` as an error shows it, clipped; Python will not turn an integer of thousands
    of digits (``0xfff…`` in YAML) into text, so that is named instead."""
    try:
        return _clip(repr(value))
    except ValueError:
        return "a number thousands of digits long"


def scene_from_dict(data: object, *, source: str = "<scene>") -> Scene:
    """Validate plain data and build a Scene; raises SceneError naming ``source`` and the key."""
    return _scene_from(data, _Reader(source, {}), default_name=Path(source).stem)


def _scene_from(data: object, r: _Reader, *, default_name: str) -> Scene:
    top = r.mapping(
        data,
        (),
        required=("target", "buildings"),
        optional=("version", "name", "description", "origin", "ground", "sky", "lighting"),
    )
    version = top.get("version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        r.fail(
            ("version",), f"unsupported scene format version {version!r} (this is {FORMAT_VERSION})"
        )
    name = r.text(top.get("name", default_name), ("name",))
    description = r.text(top.get("description", ""), ("description",))

    origin = r.mapping(
        top.get("origin", {}), ("origin",), (), ("lat_deg", "lon_deg", "alt_amsl_m", "heading_deg")
    )
    lat = r.number(origin.get("lat_deg", 0.0), ("origin", "lat_deg"))
    lon = r.number(origin.get("lon_deg", 0.0), ("origin", "lon_deg"))
    if not -90.0 <= lat <= 90.0:
        r.fail(("origin", "lat_deg"), f"latitude must be in [-90, 90], got {lat}")
    if not -180.0 <= lon <= 180.0:
        r.fail(("origin", "lon_deg"), f"longitude must be in [-180, 180], got {lon}")
    home = GeoPoint(lat, lon, r.number(origin.get("alt_amsl_m", 0.0), ("origin", "alt_amsl_m")))
    heading = r.number(origin.get("heading_deg", 0.0), ("origin", "heading_deg"))

    ground_rgb, areas, texture = read_ground(
        top.get("ground", {}), r, default_rgb=DEFAULT_GROUND_RGB
    )
    sky = r.mapping(top.get("sky", {}), ("sky",), (), ("color",))
    sky_rgb = r.color(sky.get("color", list(DEFAULT_SKY_RGB)), ("sky", "color"))
    lighting = _lighting_from(top.get("lighting", {}), r)

    raw_buildings = r.sequence(top["buildings"], ("buildings",), most=limits.MAX_BUILDINGS)
    if not raw_buildings:
        r.fail(("buildings",), "a scene needs at least one building")
    buildings = tuple(_building_from(b, ("buildings", i), r) for i, b in enumerate(raw_buildings))
    names = [b.name for b in buildings]
    for i, n in enumerate(names):
        if n in names[:i]:
            r.fail(("buildings", i, "name"), f"duplicate building name {n!r}")
    _check_buildings_apart(buildings, r)

    target = r.text(top["target"], ("target",))
    if target not in names:
        r.fail(("target",), f"no building named {target!r}; buildings: {', '.join(names)}")
    return Scene(
        name=name,
        home=home,
        home_heading_deg=heading,
        buildings=buildings,
        target=target,
        ground_rgb=ground_rgb,
        sky_rgb=sky_rgb,
        lighting=lighting,
        description=description,
        ground_areas=areas,
        ground_texture=texture,
    )


def _lighting_from(value: object, r: _Reader) -> Lighting:
    d = r.mapping(value, ("lighting",), (), ("sun_azimuth_deg", "sun_elevation_deg", "ambient"))
    default = Lighting()
    az = r.number(
        d.get("sun_azimuth_deg", default.sun_azimuth_deg), ("lighting", "sun_azimuth_deg")
    )
    el_path: KeyPath = ("lighting", "sun_elevation_deg")
    el = r.number(d.get("sun_elevation_deg", default.sun_elevation_deg), el_path)
    if not 0.0 < el <= 90.0:
        r.fail(el_path, f"sun elevation must be in (0, 90] degrees, got {el}")
    amb = r.number(d.get("ambient", default.ambient), ("lighting", "ambient"))
    if not 0.0 <= amb <= 1.0:
        r.fail(("lighting", "ambient"), f"ambient must be in [0, 1], got {amb}")
    return Lighting(az, el, amb)


def _building_from(value: object, path: KeyPath, r: _Reader) -> Building:
    d = r.mapping(value, path, ("name", "color", "blocks"))
    name = r.text(d["name"], (*path, "name"))
    if not name.strip() or any(c in name for c in "\n\r\t"):
        r.fail((*path, "name"), f"building name must be a non-empty single line, got {name!r}")
    color = r.color(d["color"], (*path, "color"))
    raw_blocks = r.sequence(d["blocks"], (*path, "blocks"), most=limits.MAX_BLOCKS)
    if not raw_blocks:
        r.fail((*path, "blocks"), "a building needs at least one block")
    blocks = tuple(_block_from(b, (*path, "blocks", i), r) for i, b in enumerate(raw_blocks))

    def stacked(i: int, j: int) -> bool:  # one above the other: no overlap in space
        a, b = blocks[i], blocks[j]
        return min(a.top_m, b.top_m) - max(a.base_m, b.base_m) <= 0.0

    clash = _first_overlap([shapely.Polygon(b.footprint_enu_m) for b in blocks], skip=stacked)
    if clash is not None:
        i, j = clash
        r.fail((*path, "blocks", i), f"overlaps blocks[{j}] of the same building")
    return Building(name, color, blocks)


def _block_from(value: object, path: KeyPath, r: _Reader) -> Block:
    d = r.mapping(value, path, ("footprint", "top_m"), ("base_m",))
    ring = r.ring(d["footprint"], (*path, "footprint"), what="footprint")
    base = r.number(d.get("base_m", 0.0), (*path, "base_m"))
    top = r.number(d["top_m"], (*path, "top_m"))
    if base < 0.0:
        r.fail((*path, "base_m"), f"base must be >= 0, got {base}")
    if top <= base:
        r.fail((*path, "top_m"), f"top ({top}) must be above base ({base})")
    if top > limits.MAX_HEIGHT_M:
        r.fail((*path, "top_m"), f"at most {limits.MAX_HEIGHT_M:g} m, got {top}")
    return Block(ring, base, top)


def _first_overlap(
    shapes: Sequence[shapely.Geometry], *, skip: Callable[[int, int], bool] | None = None
) -> tuple[int, int] | None:
    """The first pair ``(i, j)``, ``j < i``, in that order, whose shapes share more than a
    touch; pairs ``skip`` excuses do not count. A spatial index keeps this near-linear."""
    tree = shapely.STRtree(shapes)
    near_i, near_j = tree.query(shapes, predicate="intersects")
    for i, j in sorted((int(i), int(j)) for i, j in zip(near_i, near_j, strict=True) if j < i):
        if skip is not None and skip(i, j):
            continue
        if shapes[i].intersection(shapes[j]).area > _OVERLAP_M2:
            return i, j
    return None


def _check_buildings_apart(buildings: Sequence[Building], r: _Reader) -> None:
    shapes = [
        shapely.unary_union([shapely.Polygon(blk.footprint_enu_m) for blk in b.blocks])
        for b in buildings
    ]
    clash = _first_overlap(shapes)
    if clash is not None:
        i, j = clash
        r.fail(
            ("buildings", i),
            f"building {buildings[i].name!r} overlaps building {buildings[j].name!r}",
        )


# --------------------------------------------------------------------------- files


def builtin_scene_names() -> tuple[str, ...]:
    """Names of the scenes shipped with uavtool, sorted."""
    folder = resources.files("uavtool.world") / "scenes"
    return tuple(sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml")))


def load_scene(name_or_path: str | Path) -> Scene:
    """Load a built-in scene by name (``"paper"``) or a YAML/TOML/JSON scene file.

    Raises SceneError (exit code 2) for a missing file or any invalid content.
    """
    text_name = str(name_or_path)
    if isinstance(name_or_path, str) and text_name in builtin_scene_names():
        ref = resources.files("uavtool.world") / "scenes" / f"{text_name}.yaml"
        return _parse(ref.read_text(encoding="utf-8"), source=f"{text_name}.yaml", suffix=".yaml")
    path = Path(name_or_path)
    if not path.is_file():
        known = ", ".join(builtin_scene_names())
        raise SceneError(f"{path}: no such scene file (built-in scenes: {known})")
    try:
        if path.stat().st_size > limits.MAX_FILE_BYTES:
            raise SceneError(f"{path}: larger than {limits.MAX_FILE_BYTES >> 10} KiB, not a scene")
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"{path}: cannot read scene file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    return _parse(text, source=str(path), suffix=path.suffix.lower())


def parse_scene(text: str, *, source: str, suffix: str = ".yaml") -> Scene:
    """Parse scene file content; ``suffix`` (.yaml/.yml/.toml/.json) picks the syntax."""
    return _parse(text, source=source, suffix=suffix)


def _parse(text: str, *, source: str, suffix: str) -> Scene:
    data, lines = parse_text(text, source=source, suffix=suffix)
    return _scene_from(data, _Reader(source, lines), default_name=Path(source).stem)
