"""Recognition accuracy: the syntactic matcher vs OpenCV's Hu-moment ``cv2.matchShapes``.

For each seeded random scene (``uavtool.world.generator``, seeds listed in the output) the
target bitmap is the target building's footprint drawn from above (north up, 10 px/m, like
the paper's Fig. 4). Every building of the scene is photographed as the mission does it:
from 20 m above a point within 2 m of its centroid (the error of a point of interest taken
from the 45 m overview), random heading, without and with sensor noise. Its shape is the
roof of its colour nearest the image centre.

The generator makes buildings up to 12 m across and 10 m tall, and at 20 m a 60° camera
sees 12 m by 9 m of a 10 m roof: many roofs do not fit the photo. A roof cut by the image
border is not judged — the matcher marks the match not ``judgeable``, and a mission would
have to photograph it from higher — so it is never a scene's top-1 and never a false match,
and a scene whose target is cut is counted apart (how its cut outline scored is reported for
information). A scene is recognised when the target's score is the best of the judgeable
frames (strictly: a tie is an error). The false-match rate is the share of other
buildings' judgeable frames scoring at or above the threshold; those whose true footprint
is the target's shape up to scale and rotation (area-normalised IoU ≥ 0.9 at the best
rotation) cannot be told apart by shape alone and are counted too.

Each scene is one task of the sweep machinery (:func:`uavtool.sweep.dispatch.run_tasks` on a
local Dask cluster, or ``--scheduler``); its counts are one row of a table (``--out`` keeps it
as Parquet or CSV), summed here in seed order. The camera positions are drawn by the driver
from one seeded generator, in seed order, as when the scenes were judged one after another:
the figures do not depend on the number of workers.

    python benchmarks/bench_vision_recognition.py [--quick] [--scenes 200] [--buildings 5]
        [--workers 2 | --scheduler ADDRESS] [--out TABLE.parquet]

``--quick``: 20 scenes (``--scenes 20``: a false match among them), the table written to a
temporary folder unless ``--out`` is given.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import pyarrow as pa
import shapely
from shapely import affinity

from uavtool.camera import CameraPose, Intrinsics
from uavtool.sweep.cluster import open_client
from uavtool.sweep.dispatch import run_tasks
from uavtool.sweep.table import write_table
from uavtool.vision import RecognizeParams, Shape, VectorizeParams, match_shapes, vectorize
from uavtool.vision.model3d import central_shape, same_colour
from uavtool.world import render
from uavtool.world.generator import generate_scene

K = Intrinsics.from_hfov()
ALT_M = 20.0
MAX_POS_ERR_M = 2.0
NADIR = VectorizeParams(roof_only=True)
SAME_SHAPE_IOU = 0.9


def target_bitmap(footprint: tuple[tuple[float, float], ...], colour: tuple[int, int, int]):
    """The footprint drawn north-up on white, 10 px per metre."""
    pts = np.array(footprint, dtype=np.float64)
    pts = (pts - pts.min(axis=0)) * 10.0 + 40.0
    pts[:, 1] = pts[:, 1].max() + 40.0 - pts[:, 1] + 40.0  # north up: flip y
    size = (int(pts[:, 0].max()) + 40, int(pts[:, 1].max()) + 40)
    img = np.full((size[1], size[0], 3), 255, np.uint8)
    cv2.fillPoly(img, [np.round(pts * 16).astype(np.int32)], colour, shift=4)
    return img


def _contour(shape: Shape) -> np.ndarray:
    return shape.polygon_px.astype(np.float32).reshape(-1, 1, 2)


def same_shape_iou(a: tuple[tuple[float, float], ...], b: tuple[tuple[float, float], ...]):
    """IoU of two footprints scaled to unit area about their centroids, at the best of 180
    rotations of the second (no mirroring)."""

    def unit(fp):
        p = shapely.Polygon(fp)
        c = p.centroid
        s = 1.0 / math.sqrt(p.area)
        return affinity.scale(affinity.translate(p, -c.x, -c.y), s, s, origin=(0, 0))

    pa, pb = unit(a), unit(b)
    return max(
        pa.intersection(q).area / pa.union(q).area
        for q in (affinity.rotate(pb, d, origin=(0, 0)) for d in range(0, 360, 2))
    )


COUNTS = (
    "frames",
    "target_cut",
    "cut_ours_top1",
    "cut_hu_top1",
    "ours_top1",
    "hu_top1",
    "misses",  # judgeable targets scoring below the threshold
    "others",  # judgeable frames of other buildings
    "false",
    "false_same_shape",
    "no_shape",
)
MODES = {"clean": False, "noise": True}


@dataclass
class Tally:
    scenes: int = 0
    frames: int = 0
    target_cut: int = 0
    cut_ours_top1: int = 0
    cut_hu_top1: int = 0
    ours_top1: int = 0
    hu_top1: int = 0
    misses: int = 0
    others: int = 0
    false: int = 0
    false_same_shape: int = 0
    no_shape: int = 0
    errors: list[str] = field(default_factory=list)

    def add(self, row: dict, mode: str) -> None:
        """Add one scene's row (the columns ``MODE.COUNT`` and ``MODE.errors``)."""
        self.scenes += 1
        for name in COUNTS:
            setattr(self, name, getattr(self, name) + row[f"{mode}.{name}"])
        self.errors += json.loads(row[f"{mode}.errors"])


def camera_draws(seeds: list[int], buildings: int) -> list[tuple[float, ...]]:
    """Three uniform draws per building (position error radius, its direction, heading) for
    each scene, from one generator in seed order."""
    rng = random.Random(4)
    return [tuple(rng.random() for _ in range(3 * buildings)) for _ in seeds]


def judge_scene(seed: int, buildings: int, draws: tuple[float, ...]) -> dict:
    """One scene, without and with sensor noise: its row of counts (a Dask task)."""
    params = RecognizeParams()
    scene = generate_scene(seed=seed, buildings=buildings)
    tb = scene.target_building
    ti = [b.name for b in scene.buildings].index(scene.target)
    target = max(
        vectorize(target_bitmap(tb.blocks[0].footprint_enu_m, tb.color_rgb)),
        key=lambda s: s.area_px,
    )
    poses = []
    for i, b in enumerate(scene.buildings):
        cx, cy = np.array(b.blocks[0].footprint_enu_m).mean(axis=0)
        r = MAX_POS_ERR_M * math.sqrt(draws[3 * i])
        a = draws[3 * i + 1] * 2 * math.pi
        heading = draws[3 * i + 2] * 360.0
        poses.append(
            CameraPose((cx + r * math.cos(a), cy + r * math.sin(a), ALT_M), heading, -90.0)
        )
    row: dict = {"seed": seed}
    for mode, noise in MODES.items():
        st = dict.fromkeys(COUNTS, 0)
        errors: list[str] = []
        ours: list[float | None] = []  # None: not judgeable (or no shape)
        hu: list[float | None] = []
        raw: list[tuple[float, float]] = []  # every frame's scores, cut or not
        for i, (b, pose) in enumerate(zip(scene.buildings, poses, strict=True)):
            frame = render(scene, pose, K, noise_seed=seed * 100 + i if noise else None)
            shapes = vectorize(frame, NADIR)
            # The building under the camera: its colour (the mission knows it from the
            # overview), else the central shape.
            own = same_colour(shapes, b.color_rgb, hue_tolerance_deg=8.0)
            cand = central_shape(own or shapes, K)
            st["frames"] += 1
            if cand is None:
                st["no_shape"] += 1
                ours.append(None)
                hu.append(None)
                raw.append((0.0, math.inf))
                continue
            m = match_shapes(target, cand, params)
            h = cv2.matchShapes(_contour(target), _contour(cand), cv2.CONTOURS_MATCH_I1, 0.0)
            raw.append((m.score, h))
            ours.append(m.score if m.judgeable else None)
            hu.append(h if m.judgeable else None)
            if i != ti and m.judgeable:
                st["others"] += 1
                if m.score >= params.threshold:
                    st["false"] += 1
                    fp = b.blocks[0].footprint_enu_m
                    same = same_shape_iou(tb.blocks[0].footprint_enu_m, fp)
                    st["false_same_shape"] += same >= SAME_SHAPE_IOU
        if ours[ti] is None:
            st["target_cut"] += 1
            scores = [s for s, _ in raw]
            st["cut_ours_top1"] += int(np.argmax(scores)) == ti
            st["cut_hu_top1"] += int(np.argmin([d for _, d in raw])) == ti
        else:
            t_score, t_hu = ours[ti], hu[ti]
            assert t_score is not None
            assert t_hu is not None
            rivals = [(s, d) for k, (s, d) in enumerate(zip(ours, hu, strict=True)) if k != ti]
            ok = all(s is None or s < t_score for s, _ in rivals)
            st["ours_top1"] += ok
            st["hu_top1"] += all(d is None or d > t_hu for _, d in rivals)
            st["misses"] += t_score < params.threshold
            if not ok:
                errors.append(
                    f"seed {seed}: target {t_score:.3f}, others "
                    + ", ".join("cut" if s is None else f"{s:.3f}" for s, _ in rivals)
                )
        row |= {f"{mode}.{k}": int(v) for k, v in st.items()}
        row[f"{mode}.errors"] = json.dumps(errors)
    return row


def judge_all(
    seeds: list[int], buildings: int, scheduler: str | None, workers: int | None
) -> list[dict]:
    """Every scene's row, in seed order."""
    items = [(s, buildings, d) for s, d in zip(seeds, camera_draws(seeds, buildings), strict=True)]
    rows: dict[int, dict] = {}
    with open_client(scheduler, workers=workers) as client:
        for task in run_tasks(client, judge_scene, items):
            if task.error is not None:
                raise task.error
            rows[task.index] = task.result
    return [rows[i] for i in range(len(items))]


def run(
    scenes: int,
    buildings: int,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    out: Path | None = None,
) -> None:
    params = RecognizeParams()
    seeds = list(range(1000, 1000 + scenes))
    t0 = time.perf_counter()
    rows = judge_all(seeds, buildings, scheduler, workers)
    elapsed = time.perf_counter() - t0
    if out is not None:
        write_table(pa.Table.from_pylist(rows), out)
    tallies = {noise: Tally() for noise in MODES.values()}
    for row in rows:
        for mode, noise in MODES.items():
            tallies[noise].add(row, mode)
    print(
        f"seeds {seeds[0]}..{seeds[-1]} ({scenes} scenes x {buildings} buildings), "
        f"{ALT_M:.0f} m nadir, heading random, position error <= {MAX_POS_ERR_M} m; "
        f"threshold {params.threshold}; {elapsed:.0f} s"
    )
    for noise, st in tallies.items():
        n = st.scenes - st.target_cut
        judged = max(n, 1)  # a short run may have every target cut
        print(
            f"{'noise' if noise else 'clean'}: {st.frames} frames; target complete in {n} "
            f"scenes: top-1 syntactic {st.ours_top1}/{n} = {100 * st.ours_top1 / judged:.1f}% "
            f"(errors {n - st.ours_top1}), Hu matchShapes {st.hu_top1}/{n} = "
            f"{100 * st.hu_top1 / judged:.1f}% (errors {n - st.hu_top1}); target below threshold "
            f"{st.misses}/{n}; false matches {st.false}/{st.others} = "
            f"{100 * st.false / max(st.others, 1):.1f}% (same shape up to scale: "
            f"{st.false_same_shape})"
        )
        print(
            f"       target cut by the border (not judged) in {st.target_cut}/{st.scenes} "
            f"scenes; judged anyway, top-1 would be syntactic {st.cut_ours_top1}, Hu "
            f"{st.cut_hu_top1}; frames without a shape: {st.no_shape}"
        )
        for line in st.errors:
            print(f"       error: {line}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="the smallest run: --scenes 20")
    ap.add_argument("--scenes", type=int, default=200, help="default: %(default)s")
    ap.add_argument("--buildings", type=int, default=5)
    ap.add_argument("--workers", type=int, default=None, help="default: one per core")
    ap.add_argument("--scheduler", default=None, help="a running Dask scheduler")
    ap.add_argument("--out", type=Path, default=None, help="write the per-scene table here")
    if ap.parse_known_args()[0].quick:
        ap.set_defaults(scenes=20)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = a.out or (Path(tmp) / "scenes.parquet" if a.quick else None)  # the table too
        run(a.scenes, a.buildings, scheduler=a.scheduler, workers=a.workers, out=out)
