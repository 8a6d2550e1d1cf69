"""Recognition accuracy: the syntactic matcher vs OpenCV's Hu-moment ``cv2.matchShapes``.

For each seeded random scene (``uavtool.world.generator``, seeds listed in the output) the
target bitmap is the target building's footprint drawn from above (north up, like the
paper's Fig. 4). Every building of the scene is photographed from 20 m above its centroid
with a random heading and a random position error of up to 2 m, without and with sensor
noise. A scene is recognised when the target's frame scores best (top-1); the false-match
rate is the share of other buildings' frames scoring at or above the threshold.

    python benchmarks/bench_vision_recognition.py [--scenes 60] [--buildings 5]
"""

from __future__ import annotations

import argparse
import math
import random
import time

import cv2
import numpy as np

from uavtool.camera import CameraPose, Intrinsics
from uavtool.vision import RecognizeParams, Shape, VectorizeParams, match_shapes, vectorize
from uavtool.vision.model3d import central_shape, same_colour
from uavtool.world import render
from uavtool.world.generator import generate_scene

K = Intrinsics.from_hfov()
ALT_M = 20.0
MAX_POS_ERR_M = 2.0
NADIR = VectorizeParams(roof_only=True)


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


def run(scenes: int, buildings: int) -> None:
    params = RecognizeParams()
    seeds = list(range(1000, 1000 + scenes))
    rng = random.Random(4)
    stats = {
        noise: {
            "frames": 0,
            "cut": 0,
            "ours_top1": 0,
            "hu_top1": 0,
            "false": 0,
            "others": 0,
            "missed": 0,
        }
        for noise in (False, True)
    }
    t0 = time.perf_counter()
    for seed in seeds:
        scene = generate_scene(seed=seed, buildings=buildings)
        tb = scene.target_building
        target = max(
            vectorize(target_bitmap(tb.blocks[0].footprint_enu_m, tb.color_rgb)),
            key=lambda s: s.area_px,
        )
        poses = []
        for b in scene.buildings:
            fp = np.array(b.blocks[0].footprint_enu_m)
            cx, cy = fp.mean(axis=0)
            r = MAX_POS_ERR_M * math.sqrt(rng.random())
            a = rng.random() * 2 * math.pi
            poses.append(
                CameraPose(
                    (cx + r * math.cos(a), cy + r * math.sin(a), ALT_M), rng.random() * 360.0, -90.0
                )
            )
        for noise in (False, True):
            st = stats[noise]
            ours, hu = [], []
            for i, (b, pose) in enumerate(zip(scene.buildings, poses, strict=True)):
                frame = render(scene, pose, K, noise_seed=seed * 100 + i if noise else None)
                shapes = vectorize(frame, NADIR)
                # The building under the camera: its colour (the mission knows it from the
                # overview), else the central shape.
                own = same_colour(shapes, b.color_rgb, hue_tolerance_deg=8.0)
                cand = central_shape(own or shapes, K)
                st["frames"] += 1
                if cand is None:
                    ours.append(0.0)
                    hu.append(math.inf)
                    st["missed"] += 1
                    continue
                score = match_shapes(target, cand, params).score
                st["cut"] += b.name == scene.target and cand.cut_by_border
                ours.append(score)
                hu.append(
                    cv2.matchShapes(_contour(target), _contour(cand), cv2.CONTOURS_MATCH_I1, 0.0)
                )
                if b.name != scene.target:
                    st["others"] += 1
                    st["false"] += score >= params.threshold
            ti = [b.name for b in scene.buildings].index(scene.target)
            st["ours_top1"] += int(np.argmax(ours)) == ti
            st["hu_top1"] += int(np.argmin(hu)) == ti
    elapsed = time.perf_counter() - t0
    print(
        f"seeds {seeds[0]}..{seeds[-1]} ({scenes} scenes x {buildings} buildings), "
        f"20 m nadir, heading random, position error <= {MAX_POS_ERR_M} m; {elapsed:.0f} s"
    )
    for noise, st in stats.items():
        n = scenes
        print(
            f"{'noise' if noise else 'clean':5s}: {st['frames']} frames | top-1 syntactic "
            f"{st['ours_top1']}/{n} = {100 * st['ours_top1'] / n:.1f}% "
            f"(errors {n - st['ours_top1']}) | top-1 Hu matchShapes {st['hu_top1']}/{n} = "
            f"{100 * st['hu_top1'] / n:.1f}% (errors {n - st['hu_top1']}) | false matches "
            f"at {params.threshold}: {st['false']}/{st['others']} = "
            f"{100 * st['false'] / max(st['others'], 1):.1f}% | no shape: {st['missed']} | "
            f"target cut by the frame border: {st['cut']}/{n}"
        )


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=60)
    ap.add_argument("--buildings", type=int, default=5)
    a = ap.parse_args()
    run(a.scenes, a.buildings)
