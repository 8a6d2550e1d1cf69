"""``/mission/scene``: every update carries every entity known so far, so a viewer that seeks
(it shows the last message of a topic before the playhead) draws the whole picture."""

from __future__ import annotations

from pathlib import Path

from uavtool.recording import RecordingReader, SceneMarkers
from uavtool.recording.topics import SCENE

PAPER = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def test_each_scene_update_holds_everything_known_by_then() -> None:
    with RecordingReader(PAPER) as reader:
        updates = [e.value for e in reader.entries([SCENE]) if isinstance(e.value, SceneMarkers)]
    kinds = [{e.entity_id for e in u.entities} for u in updates]
    assert kinds[-1] == {"route", "photos", "pois", "viewpoints"}
    planned = next(i for i, k in enumerate(kinds) if "pois" in k)
    assert all("pois" in k and {"route", "photos"} <= k for k in kinds[planned:])
    routes = [len(next(e for e in u.entities if e.entity_id == "route").line_m) for u in updates]
    assert routes == sorted(routes) and routes[-1] > 100  # the route only grows
