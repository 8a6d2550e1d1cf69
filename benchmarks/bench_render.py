"""Renderer speed and correctness: ours vs a naive numpy z-buffer vs OpenCV painter's order.

Run on demand (never in the test suite; in CI with ``--quick``: one round, ``--rounds 1``):

    python benchmarks/bench_render.py [--quick] [--rounds 7] [--scenes paper,dense]

For each scene and image size, every method renders the same mission-like poses (overview
from 45 m, nadir from 20 m over the target, front/right/oblique views of it); rounds are
interleaved and the median round is reported as frames per second, on one core. The
differing-pixel share is measured against the naive z-buffer, which is the ground truth.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import cv2
import numpy as np

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world import Scene, load_scene, render
from uavtool.world.raster import prepare, project_faces
from uavtool.world.reference import render_reference
from uavtool.world.render import ImageRGB

Renderer = Callable[[Scene, CameraPose, Intrinsics], ImageRGB]


def render_painter(scene: Scene, pose: CameraPose, intrinsics: Intrinsics) -> ImageRGB:
    """Painter's algorithm: front faces sorted far to near, filled by cv2.fillConvexPoly."""
    prep = prepare(scene)
    h, w = intrinsics.height_px, intrinsics.width_px
    img = np.empty((h, w, 3), dtype=np.uint8)
    p = np.radians(pose.pitch_deg)
    horizon = (
        int(np.clip(np.ceil(intrinsics.cy_px + intrinsics.fy_px * np.tan(p)), 0, h))
        if p > -1.5
        else 0
    )
    img[:horizon] = scene.sky_rgb
    img[horizon:] = scene.ground_rgb
    faces = project_faces(prep, pose, intrinsics, cull=True)
    faces.sort(key=lambda f: -sum(f.depth_m) / len(f.depth_m))
    for f in faces:
        pts = np.round(np.stack([f.u_px, f.v_px], axis=1) * 256.0).astype(np.int32)
        if np.abs(pts).max() > 2**28:
            continue
        cv2.fillConvexPoly(img, pts, prep.face_rgb[f.face], lineType=cv2.LINE_8, shift=8)
    return img


def poses_for(scene: Scene) -> list[CameraPose]:
    target = scene.target_building
    xs = [x for b in target.blocks for x, _ in b.footprint_enu_m]
    ys = [y for b in target.blocks for _, y in b.footprint_enu_m]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return [
        CameraPose((0.0, 0.0, 45.0), 0.0, -90.0),
        CameraPose((cx, cy, 20.0), 0.0, -90.0),
        CameraPose((cx, min(ys) - 20.0, 3.0), 0.0, 0.0),
        CameraPose((max(xs) + 20.0, cy, 3.0), 270.0, 0.0),
        CameraPose((cx - 20.0, cy - 20.0, 15.0), 45.0, -30.0),
    ]


def fps(
    renderer: Renderer, scene: Scene, poses: list[CameraPose], intr: Intrinsics, repeat: int
) -> float:
    start = time.perf_counter()
    for _ in range(repeat):
        for pose in poses:
            renderer(scene, pose, intr)
    return repeat * len(poses) / (time.perf_counter() - start)


def differing_share(
    renderer: Renderer, scene: Scene, poses: list[CameraPose], intr: Intrinsics
) -> float:
    bad = total = 0
    for pose in poses:
        a, b = renderer(scene, pose, intr), render_reference(scene, pose, intr)
        bad += int(np.any(a != b, axis=2).sum())
        total += a.shape[0] * a.shape[1]
    return bad / total


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --rounds 1")
    parser.add_argument("--rounds", type=int, default=7, help="default: %(default)s")
    parser.add_argument("--scenes", default="paper,dense", help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(rounds=1)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    methods: dict[str, Renderer] = {
        "naive z-buffer": render_reference,
        "painter (cv2)": render_painter,
        "ours": render,
    }
    print(
        f"{'scene':8s} {'size':>9s} "
        + " ".join(f"{m:>15s}" for m in methods)
        + "  ours/naive ours/painter  diff(ours) diff(painter)"
    )
    for name in args.scenes.split(","):
        scene = load_scene(name)
        poses = poses_for(scene)
        for w, h in ((640, 480), (1280, 960)):
            intr = Intrinsics.from_hfov(width_px=w, height_px=h)
            for m in methods.values():  # warm caches
                m(scene, poses[0], intr)
            rounds: dict[str, list[float]] = {m: [] for m in methods}
            for _ in range(args.rounds):
                for label, m in methods.items():
                    rounds[label].append(
                        fps(m, scene, poses, intr, repeat=2 if label == "naive z-buffer" else 6)
                    )
            med = {label: statistics.median(v) for label, v in rounds.items()}
            ours_diff = differing_share(render, scene, poses, intr)
            painter_diff = differing_share(render_painter, scene, poses, intr)
            print(
                f"{name:8s} {w:4d}x{h:<4d} "
                + " ".join(f"{med[m]:11.1f} fps" for m in methods)
                + f"  {med['ours'] / med['naive z-buffer']:9.1f}x"
                + f" {med['ours'] / med['painter (cv2)']:10.2f}x"
                + f"  {100 * ours_diff:9.4f}% {100 * painter_diff:11.3f}%"
            )


if __name__ == "__main__":
    main()
