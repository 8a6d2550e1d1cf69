"""Per-frame re-analysis: the mission's vision (vectorize, and for photos at points of interest
the comparison with the target) re-run on every recorded photo, and what changed."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from uavtool.mission import Params, Photo, SearchMission
from uavtool.mission.analysis import judge, nadir_shapes, side_shapes, stepped, target_shapes
from uavtool.replay.load import RecordedFlight

_SIDE_TAGS = ("front", "right", "diagonal")


@dataclass(frozen=True, slots=True)
class FrameChange:
    """One photo, recorded vs re-analysed: shape counts, and for points of interest the
    candidate's score and the match decision (None where the frame was not judged)."""

    frame_index: int
    tag: str
    shapes_before: int
    shapes_after: int
    score_before: float | None
    score_after: float | None
    matched_before: bool | None
    matched_after: bool | None
    best_after: float | None = None
    """The best score of any shape in the frame (the mission judges only the one the look
    was aimed at)."""

    @property
    def changed(self) -> bool:
        return (
            self.shapes_before != self.shapes_after
            or self.score_before != self.score_after
            or self.matched_before != self.matched_after
        )

    def describe(self) -> str:
        parts = [f"shapes {self.shapes_before} → {self.shapes_after}"]
        if self.score_after is not None:
            before = "—" if self.score_before is None else f"{self.score_before:.3f}"
            parts.append(f"match score of the aimed-at shape {before} → {self.score_after:.3f}")
            if self.best_after is not None and self.best_after > self.score_after:
                parts.append(f"best shape in the frame {self.best_after:.3f}")
            if self.matched_before == self.matched_after:
                parts.append("decision unchanged")
            else:
                parts.append(f"decision {_word(self.matched_before)} → {_word(self.matched_after)}")
        return f"frame {self.frame_index} ({self.tag}): " + ", ".join(parts)


def reanalyse_frames(flight: RecordedFlight, params: Params) -> list[FrameChange]:
    """Every recorded photo through the mission's vision with ``params``, beside the recorded
    results (the built-in mission's vision; none for another mission)."""
    if not issubclass(flight.mission, SearchMission) or flight.target_rgb is None:
        return []
    recorded_shapes: dict[int, int] = {}
    recorded_judgement: dict[int, dict[str, Any]] = {}
    poi_colours: dict[int, tuple[int, int, int]] = {}  # what each look was aimed at
    for out in flight.outputs:
        kind = out.data.get("type")
        if kind == "Shapes":
            recorded_shapes[int(out.data["frame_index"])] = len(out.data["shapes"])
        elif kind == "Recognition":
            recorded_judgement[int(out.data["frame_index"])] = out.data
        elif kind == "Plan":
            for poi in out.data["pois"]:
                r, g, b = poi["colour_rgb"]
                poi_colours[int(poi["index"])] = (int(r), int(g), int(b))
    _, target = target_shapes(params, flight.target_rgb)
    target_stepped = stepped(flight.target_rgb, target)
    changes = []
    for obs in flight.observations:
        if not isinstance(obs, Photo):
            continue
        side = obs.tag.split("-")[0] in _SIDE_TAGS  # "front", or "front-2" for a retake
        shapes = side_shapes(params, obs.image_rgb) if side else nadir_shapes(params, obs.image_rgb)
        score_after = matched_after = score_before = matched_before = best_after = None
        # The looks ("poi-3", "poi-3-2") are judged; "poi-3-roof" only measures a height.
        kind, *numbers = obs.tag.split("-")
        if kind == "poi" and numbers and all(n.isdigit() for n in numbers):
            aimed = poi_colours.get(int(numbers[0]))
            j = judge(
                params,
                target,
                shapes,
                obs.intrinsics,
                aimed,
                target_stepped=target_stepped,
            )
            score_after, matched_after = j.score, j.matched
            best_after = max(j.scores, default=None)
            before = recorded_judgement.get(obs.frame_index)
            if before is not None:
                score_before, matched_before = float(before["score"]), bool(before["matched"])
        changes.append(
            FrameChange(
                obs.frame_index,
                obs.tag,
                recorded_shapes.get(obs.frame_index, 0),
                len(shapes),
                score_before,
                score_after,
                matched_before,
                matched_after,
                best_after,
            )
        )
    return changes


def _word(matched: bool | None) -> str:
    return "—" if matched is None else ("match" if matched else "no match")
