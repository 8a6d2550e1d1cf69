"""Scenes of a sweep: built-in names, files, and seeded generators, loaded where a flight runs
(a generated scene is made on the worker from its seed, not shipped)."""

from __future__ import annotations

from typing import Any

from uavtool.sweep.spec import SceneKind, SceneSource
from uavtool.world import Scene, load_scene


def scene_label(source: SceneSource, seed: int | None) -> str:
    """The scene column of the table: ``paper``, ``file:yard.yaml``, ``hard:17``, ``random:3``."""
    if source.kind is SceneKind.BUILTIN:
        return source.name
    if source.kind is SceneKind.FILE:
        return f"file:{source.name}"
    return f"{source.kind.value}:{seed}"


def load_source_scene(source: SceneSource, seed: int | None) -> Scene:
    """The scene; raises SceneError (an InputError) or TypeError for bad generator options."""
    options: dict[str, Any] = dict(source.options)
    if source.kind is SceneKind.BUILTIN:
        return load_scene(source.name)
    if source.kind is SceneKind.FILE:
        assert source.path is not None
        return load_scene(source.path)
    assert seed is not None
    if source.kind is SceneKind.HARD:
        from uavtool.world.hard import HardOptions, generate_hard_scene  # noqa: PLC0415

        return generate_hard_scene(seed=seed, options=HardOptions(**options))
    from uavtool.world.generator import generate_scene  # noqa: PLC0415

    return generate_scene(
        seed=seed,
        buildings=int(options.get("buildings", 8)),
        margin_m=float(options.get("margin_m", 4.0)),
    )
