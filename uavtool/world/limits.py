"""Limits on scene files and scene data: what a scene may hold, and how big its file may be.

A scene describes a few buildings around home (the built-in ones have 4–12). These limits are
far above any real scene and low enough that loading, validating and rendering the largest
allowed scene stays within seconds and megabytes, whatever the file holds. Each is checked
before the work it guards, and breaking one is a one-line :class:`SceneError` naming the file
and, where known, the line and key.
"""

from __future__ import annotations

# The file
MAX_FILE_BYTES = 256 * 1024
"""A scene file is at most 256 KiB (200 generated buildings take about 50 KiB)."""
MAX_DEPTH = 16
"""Mappings and lists nest at most this deep (a scene needs 7 levels)."""
MAX_NODES = 100_000
"""Values in the file, counting each use of a YAML alias as a copy of what it names: a file
of a few hundred bytes cannot stand for billions of values."""
MAX_TEXT_CHARS = 4096
"""Longest single value (a name, a description, the digits of a number)."""

# The scene
MAX_BUILDINGS = 200
MAX_BLOCKS = 32
"""Blocks per building."""
MAX_FOOTPRINT_VERTICES = 256
MAX_SCENE_VERTICES = 4096
"""Footprint vertices of all blocks together: the renderer's set-up compares every pair of
convex pieces, so this bounds its time and memory."""
MAX_GROUND_AREAS = 256
"""Flat ground areas (lawns, roads, fields); their vertices count with the footprints'."""
MAX_EXTENT_M = 10_000.0
"""Footprint coordinates lie within this many metres of home, east and north."""
MAX_HEIGHT_M = 1_000.0
"""Blocks end at most this high above the ground."""
