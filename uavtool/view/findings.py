"""`Findings`: what the mission's vision produced, drawn where it belongs.

Shapes go over the frame they were found in (and over the target picture for frame −1),
points of interest over the overview frame and in 3D, the recognizer's pick over its frame,
scores on the plots, the planned viewpoints and the built model in 3D.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import rerun as rr

from uavtool.view import entities as ent
from uavtool.view.paths import Paths

_MODEL_GAP_M = 4.0  # space between the true building and the model shown beside it

Output = Mapping[str, Any]


class Findings:
    """State of the vision outputs for one mission; ``frame`` is the photo on screen.

    ``home_en_m``: a fleet's vehicle's home in the fleet's frame. Its mission's positions
    (points of interest, viewpoints, the model) are in the fleet's frame while its entities
    are in its own, so they are drawn moved by minus its home."""

    def __init__(
        self,
        rec: rr.RecordingStream,
        paths: Paths,
        *,
        home_en_m: tuple[float, float] | None = None,
    ) -> None:
        self.rec = rec
        self.paths = paths
        self.home_en_m = home_en_m
        self.frame = -2  # no photo yet (−1 is the target picture)
        self.poi_height_m = 10.0
        self.threshold: float | None = None
        self.shape_count = 0
        self.recognitions = 0
        self.models = 0
        self._shapes: dict[int, list[Mapping[str, Any]]] = {}
        self.pois: list[Mapping[str, Any]] = []
        self._scores: dict[int, float] = {}
        self._matched: int | None = None
        self._viewpoints: tuple[Sequence[Any], list[Mapping[str, Any]]] = ([], [])

    def shapes(self, out: Output) -> None:
        frame = int(out.get("frame_index", -1))
        shapes = list(out.get("shapes") or [])
        self._shapes[frame] = shapes
        self.shape_count += len(shapes)
        if frame == -1:  # the target picture: static, like the picture itself
            ent.log_shapes(self.rec, self.paths.target_shapes, shapes=shapes, static=True)
        elif frame == self.frame:
            ent.log_shapes(self.rec, self.paths.shapes, shapes=shapes)

    def plan(self, out: Output) -> None:
        self.pois = list(out.get("pois") or [])
        self._log_pois()
        frame = int(out.get("frame_index", -1))
        if frame != self.frame:
            return
        shapes = self._shapes.get(frame, [])
        marks = [
            (p, shapes[int(p["shape_index"])])
            for p in self.pois
            if 0 <= int(p["shape_index"]) < len(shapes)
        ]
        ent.log_image_pois(
            self.rec,
            self.paths,
            centroids_px=[s["centroid_px"] for _, s in marks],
            labels=[f"poi {p['index']}" for p, _ in marks],
        )

    def recognition(self, out: Output) -> None:
        poi, score = int(out.get("poi", -1)), float(out.get("score", 0.0))
        matched = bool(out.get("matched"))
        self.recognitions += 1
        self._scores[poi] = score
        if matched:
            self._matched = poi
        ent.log_scalar(self.rec, self.paths.recognition_poi(poi), value=score)
        if self.threshold is not None:
            ent.log_scalar(self.rec, self.paths.threshold, value=self.threshold)
        self._log_pois()
        frame, candidate = int(out.get("frame_index", -1)), out.get("candidate")
        shapes = self._shapes.get(frame, [])
        if frame == self.frame and isinstance(candidate, int) and 0 <= candidate < len(shapes):
            label = f"{'MATCH' if matched else 'best'} {score:.2f}"
            ent.log_match(
                self.rec, self.paths, shape=shapes[candidate], label=label, matched=matched
            )

    def viewpoints(self, out: Output) -> list[str]:
        """Draws the planned viewpoints; returns why each failed one failed."""
        views = [out[k] for k in ("top", "front", "right") if isinstance(out.get(k), Mapping)]
        self._viewpoints = (out.get("footprint_en_m") or [], views)
        return self._draw_viewpoints(views)

    def diagonal(self, out: Output) -> None:
        """Adds the diagonal viewpoint, if there is one, to those drawn (the mission's event
        says why there is none)."""
        footprint, views = self._viewpoints
        view = out.get("viewpoint")
        if isinstance(view, Mapping) and "pos_enu_m" in view:
            self._viewpoints = (footprint, [*views, view])
            self._draw_viewpoints(self._viewpoints[1])

    def _draw_viewpoints(self, views: list[Mapping[str, Any]]) -> list[str]:
        footprint, _ = self._viewpoints
        ent.log_viewpoints(
            self.rec,
            self.paths,
            footprint_en_m=[self._here(p) for p in footprint],
            viewpoints=[self._here_view(v) for v in views],
        )
        return [
            f"viewpoint {v.get('name')}: {v.get('reason', 'failed')}"
            for v in views
            if "pos_enu_m" not in v
        ]

    def model(self, out: Output) -> None:
        verts: Sequence[Sequence[float]] = out.get("vertices_m") or []
        xs = [float(v[0]) for v in verts]
        offset = ((max(xs) - min(xs) + _MODEL_GAP_M) if xs else 0.0, 0.0, 0.0)
        if self.home_en_m is not None:  # the vertices are in the fleet's frame
            offset = (offset[0] - self.home_en_m[0], -self.home_en_m[1], 0.0)
        height_m, volume_m3 = float(out.get("height_m", 0.0)), float(out.get("volume_m3", 0.0))
        ent.log_model(
            self.rec,
            self.paths,
            vertices_m=verts,
            faces=out.get("faces") or [],
            offset_enu_m=offset,
            label=f"model: {height_m:.1f} m high, {volume_m3:.0f} m³",
        )
        self.models += 1

    def _log_pois(self) -> None:
        if not self.pois:
            return
        labels = []
        for p in self.pois:
            i = int(p["index"])
            label = f"{i}"
            if "roof_m" in p:  # recordings before roof heights were measured have none
                label += (
                    f" (roof {float(p['roof_m']):.1f} m{'' if p.get('roof_measured') else '?'})"
                )
            if i in self._scores:
                label += f": {'MATCH ' if i == self._matched else ''}{self._scores[i]:.2f}"
            labels.append(label)
        ent.log_pois(
            self.rec,
            self.paths,
            positions_en_m=[self._here(p["pos_en_m"]) for p in self.pois],
            labels=labels,
            colours_rgb=[p.get("colour_rgb") or (200, 200, 200) for p in self.pois],
            matched=[int(p["index"]) == self._matched for p in self.pois],
            height_m=self.poi_height_m,
        )

    def _here(self, pos: Sequence[Any]) -> Sequence[Any]:
        """A position of the mission's (east, north, …) in this vehicle's frame."""
        if self.home_en_m is None:
            return pos
        east, north = self.home_en_m
        return [float(pos[0]) - east, float(pos[1]) - north, *pos[2:]]

    def _here_view(self, view: Mapping[str, Any]) -> Mapping[str, Any]:
        if self.home_en_m is None or "pos_enu_m" not in view:
            return view
        return {**view, "pos_enu_m": self._here(view["pos_enu_m"])}
