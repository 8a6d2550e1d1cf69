"""Recognition scores of a flight, per building, read back from its recording: how far the
target stood out from the best other building the mission photographed."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from uavtool.recording import JsonDocument, RecordingReader
from uavtool.recording.topics import OUTPUTS
from uavtool.runner.evaluate import nearest_building
from uavtool.world import Scene


@dataclass(frozen=True, slots=True)
class Scores:
    """Best recognition score at a point of interest on the target, and on any other building
    (None: no such point photographed); ``margin`` is their difference. ``target_looks``: the
    target's score at each look, in the order the mission judged them."""

    target: float | None
    other: float | None
    target_looks: tuple[float, ...] = ()

    @property
    def margin(self) -> float | None:
        if self.target is None or self.other is None:
            return None
        return self.target - self.other


def recognition_scores(recording: Path, scene: Scene) -> Scores:
    """Scores of a lockstep recording of the built-in vehicle (its home is the scene's)."""
    pois: dict[int, tuple[float, float]] = {}
    best: dict[str, float] = {}
    looks: list[float] = []
    with RecordingReader(recording) as reader:
        for entry in reader.entries([OUTPUTS]):
            if not isinstance(entry.value, JsonDocument):
                continue
            data = entry.value.payload
            if data.get("type") == "Plan":
                pois = {int(p["index"]): (p["pos_en_m"][0], p["pos_en_m"][1]) for p in data["pois"]}
            elif data.get("type") == "Recognition" and int(data.get("poi", -1)) in pois:
                name = nearest_building(scene, pois[int(data["poi"])])
                best[name] = max(best.get(name, float("-inf")), float(data["score"]))
                if name == scene.target:
                    looks.append(float(data["score"]))
    others = [s for name, s in best.items() if name != scene.target]
    return Scores(best.get(scene.target), max(others) if others else None, tuple(looks))
