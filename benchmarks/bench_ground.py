"""What a ground texture costs the renderer: the same frames of the same scenes, flat and
textured (issue 45 item 2: at most 1.3x).

Run on demand (never in the test suite; CI runs ``--quick``):

    python benchmarks/bench_ground.py [--quick] [--rounds 15] [--seeds 1,2,3] [--size 640x480]

Each scene is ``uavtool scene random --hard --town --world --seed S`` (ground areas, any
light and ground colour, near shapes), rendered at mission-like poses (overview from 45 m,
nadir from 20 m over the target, two oblique looks at it): once with the scene's ground
texture (grain in one scene, noise in the next) and once with the texture taken off, nothing
else changed. Rounds alternate flat and textured; the ratio is the median of the rounds'
ratios, printed against the goal for ``render`` alone and for a frame with the simulated
camera's sensor noise (what a flight with sensor noise renders). The built-in ``paper``
scene (four buildings, no areas: the cheapest frames, so the dearest ratio) is measured the
same way. One core.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from dataclasses import replace

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import cv2

from uavtool.camera import CameraPose, Intrinsics
from uavtool.world import Scene, load_scene, render
from uavtool.world.ground import GroundTexture, TextureKind
from uavtool.world.hard import HardOptions, generate_hard_scene
from uavtool.world.raster import prepare

GOAL = 1.3


def scenes(seeds: list[int]) -> list[tuple[Scene, Scene]]:
    """(flat, textured) pairs: the textured one has grain or noise whatever its seed drew."""
    out = []
    for k, seed in enumerate(seeds):
        scene = generate_hard_scene(seed=seed, options=HardOptions.town().with_world())
        kind = TextureKind.GRAIN if k % 2 == 0 else TextureKind.NOISE
        texture = GroundTexture(kind, 10.0, 0.3 if kind is TextureKind.GRAIN else 2.0, seed)
        out.append((replace(scene, ground_texture=None), replace(scene, ground_texture=texture)))
    return out


def poses_for(scene: Scene) -> list[CameraPose]:
    xs = [x for b in scene.target_building.blocks for x, _ in b.footprint_enu_m]
    ys = [y for b in scene.target_building.blocks for _, y in b.footprint_enu_m]
    cx, cy = (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0
    return [
        CameraPose((0.0, 0.0, 45.0), 0.0, -90.0),
        CameraPose((cx, cy, 20.0), 30.0, -90.0),
        CameraPose((cx, cy - 25.0, 12.0), 0.0, -25.0),
        CameraPose((cx + 25.0, cy, 12.0), 270.0, -25.0),
    ]


def seconds(scene: Scene, poses: list[CameraPose], intr: Intrinsics, *, noise: bool) -> float:
    start = time.perf_counter()
    for k, pose in enumerate(poses):
        render(scene, pose, intr, noise_seed=k if noise else None)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --rounds 3")
    parser.add_argument("--rounds", type=int, default=15, help="default: %(default)s")
    parser.add_argument("--seeds", default="1,2,3,4", help="default: %(default)s")
    parser.add_argument("--size", default="640x480", help="default: %(default)s")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(rounds=3)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    w, h = (int(v) for v in args.size.lower().split("x"))
    intr = Intrinsics.from_hfov(width_px=w, height_px=h)
    paper = load_scene("paper")
    grain = GroundTexture(TextureKind.GRAIN, 10.0, 0.3, 1)
    groups = {
        "town --world": scenes([int(s) for s in args.seeds.split(",")]),
        "paper": [(paper, replace(paper, ground_texture=grain))],
    }
    for name, pairs in groups.items():
        for flat, textured in pairs:  # warm the caches: prisms, texture tiles
            prepare(flat)
            seconds(textured, poses_for(textured), intr, noise=False)
        print(f"{name}: {len(pairs)} scenes x 4 poses, {w}x{h}, {args.rounds} rounds")
        measure(pairs, intr, args.rounds)


def measure(pairs: list[tuple[Scene, Scene]], intr: Intrinsics, rounds: int) -> None:
    """Print the textured/flat ratio of rendering ``pairs``, alone and with sensor noise."""
    for noise in (False, True):
        ratios, flat_s, tex_s = [], [], []
        for _ in range(rounds):
            a = sum(seconds(f, poses_for(f), intr, noise=noise) for f, _ in pairs)
            b = sum(seconds(t, poses_for(t), intr, noise=noise) for _, t in pairs)
            ratios.append(b / a)
            flat_s.append(a)
            tex_s.append(b)
        frames = 4 * len(pairs)
        ratio = statistics.median(ratios)
        label = "render + sensor noise" if noise else "render"
        print(
            f"  {label:22s} flat {1e3 * statistics.median(flat_s) / frames:6.2f} ms/frame, "
            f"textured {1e3 * statistics.median(tex_s) / frames:6.2f} ms/frame: "
            f"{ratio:.2f}x (goal <= {GOAL}x: {'met' if ratio <= GOAL else 'NOT met'})"
        )


if __name__ == "__main__":
    main()
