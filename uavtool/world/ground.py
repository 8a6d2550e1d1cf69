"""The ground of a scene beyond its one colour: flat areas and a seeded texture.

In a scene file, under ``ground``::

    ground:
      color: [128, 128, 128]
      areas:                      # drawn in this order, later ones over earlier ones
        - {name: lawn, color: [86, 125, 62], polygon: [[-20, -5], [5, -5], [5, 12], [-20, 12]]}
      texture: {kind: grain, amplitude_dn: 8, scale_m: 0.3, seed: 4}

An area is a simple polygon at height 0 (metres east/north of home, as footprints are) with
its own colour: a lawn, a road, a car park, a field. It is not a building: no obstacle, no
height, never in the scene's building list; buildings stand over it. The texture adds
seeded offsets of at most ``amplitude_dn`` digital numbers to the ground and every area,
fixed to the ground in world metres: ``grain`` changes from one ``scale_m`` cell to the
next, ``noise`` is smooth with patches about ``scale_m`` across.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import TYPE_CHECKING, Any

from uavtool.world import limits

if TYPE_CHECKING:
    from uavtool.world.scene import RGB, _Reader
    from uavtool.world.scene_file import KeyPath

TEXTURE_AMPLITUDE_DN = (0.0, 64.0)
TEXTURE_SCALE_M = (0.02, 50.0)
TEXTURE_SEED_MAX = 2**32 - 1


class TextureKind(Enum):
    """How a ground texture varies across the ground."""

    GRAIN = "grain"  # an independent value per ``scale_m`` cell
    NOISE = "noise"  # smooth value noise, patches about ``scale_m`` across


@dataclass(frozen=True, slots=True)
class GroundTexture:
    """Seeded offsets of at most ``amplitude_dn`` (0–255 scale) added to every channel of the
    ground, fixed to the ground in world metres."""

    kind: TextureKind
    amplitude_dn: float
    scale_m: float
    seed: int


@dataclass(frozen=True, slots=True)
class GroundArea:
    """A flat, coloured patch of ground: ``polygon_enu_m`` (n, 2) a simple counter-clockwise
    ring in metres east/north of home, at height 0."""

    name: str
    color_rgb: RGB
    polygon_enu_m: tuple[tuple[float, float], ...]


def ground_to_dict(
    color_rgb: RGB, areas: Sequence[GroundArea], texture: GroundTexture | None
) -> dict[str, Any]:
    """The scene file's ``ground`` mapping; ``areas`` and ``texture`` only when there are any,
    so a scene without them is written as it always was."""
    out: dict[str, Any] = {"color": list(color_rgb)}
    if areas:
        out["areas"] = [
            {
                "name": a.name,
                "color": list(a.color_rgb),
                "polygon": [[x, y] for x, y in a.polygon_enu_m],
            }
            for a in areas
        ]
    if texture is not None:
        out["texture"] = {
            "kind": texture.kind.value,
            "amplitude_dn": texture.amplitude_dn,
            "scale_m": texture.scale_m,
            "seed": texture.seed,
        }
    return out


def read_ground(
    value: object, r: _Reader, *, default_rgb: RGB
) -> tuple[RGB, tuple[GroundArea, ...], GroundTexture | None]:
    """The ``ground`` mapping's colour, areas and texture; raises SceneError naming the key."""
    d = r.mapping(value, ("ground",), (), ("color", "areas", "texture"))
    rgb = r.color(d.get("color", list(default_rgb)), ("ground", "color"))
    raw = r.sequence(d.get("areas", []), ("ground", "areas"), most=limits.MAX_GROUND_AREAS)
    areas = tuple(_area_from(a, ("ground", "areas", i), r) for i, a in enumerate(raw))
    names = [a.name for a in areas]
    for i, n in enumerate(names):
        if n in names[:i]:
            r.fail(("ground", "areas", i, "name"), f"duplicate area name {n!r}")
    texture = None if "texture" not in d else _texture_from(d["texture"], r)
    return rgb, areas, texture


def _area_from(value: object, path: KeyPath, r: _Reader) -> GroundArea:
    d = r.mapping(value, path, ("name", "color", "polygon"))
    name = r.text(d["name"], (*path, "name"))
    if not name.strip() or any(c in name for c in "\n\r\t"):
        r.fail((*path, "name"), f"area name must be a non-empty single line, got {name!r}")
    color = r.color(d["color"], (*path, "color"))
    return GroundArea(name, color, r.ring(d["polygon"], (*path, "polygon"), what="polygon"))


def _texture_from(value: object, r: _Reader) -> GroundTexture:
    path: KeyPath = ("ground", "texture")
    d = r.mapping(value, path, ("kind",), ("amplitude_dn", "scale_m", "seed"))
    kinds = [k.value for k in TextureKind]
    if d["kind"] not in kinds:
        r.fail((*path, "kind"), f"expected one of {', '.join(kinds)}, got {d['kind']!r}")
    amp = r.number(d.get("amplitude_dn", 8.0), (*path, "amplitude_dn"))
    lo, hi = TEXTURE_AMPLITUDE_DN
    if not lo <= amp <= hi:
        r.fail((*path, "amplitude_dn"), f"must be in [{lo:g}, {hi:g}] DN, got {amp}")
    scale = r.number(d.get("scale_m", 0.5), (*path, "scale_m"))
    lo, hi = TEXTURE_SCALE_M
    if not lo <= scale <= hi:
        r.fail((*path, "scale_m"), f"must be in [{lo:g}, {hi:g}] m, got {scale}")
    seed = r.whole(d.get("seed", 0), (*path, "seed"), 0, TEXTURE_SEED_MAX)
    return GroundTexture(TextureKind(d["kind"]), amp, scale, seed)
