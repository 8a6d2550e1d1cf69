"""Recognition against the heading a look is taken at: the target photographed from above as
the mission does it, at every heading, by today's code and by a baseline commit's.

A look's heading is whatever the vehicle's yaw is when the photo is taken; a lossy link, a
slow yaw or ArduCopter's WP_YAW_BEHAVIOR make it anything. Two sets of photos, each judged as
the mission judges a look (``mission.analysis``: the photo's roofs joined, the target's
picture as ``uavtool fly`` makes it, the candidate the photo is centred on):

- ``paper``'s red building from 15, 22, 30 and 40 m above its roof, 1.3 m east and 0.7 m
  south of its centre (a point of interest is an estimate), every whole degree of heading;
- the target of each generated hard scene (``uavtool.world.hard``, seeds listed), straight
  above its centre, from where its footprint spans 35, 50 and 70 % of the photo's height
  (the mission looks from 50 %), every 10° of heading.

Printed per variant: photos judged (a target cut by the border is not judged), how many
score below 0.7 (the mission's threshold), 0.8 and 0.9, the worst and the mean score. And
the other side of it: every other building of each hard scene photographed where a look at
it would be taken (and closer), every 30°: the photos the mission would take for the target
(false matches) and their mean score.

    python benchmarks/bench_recognition_heading.py [--quick] [--scenes 60] [--first-seed 1]
        [--baseline 73c3162]

``--quick``: one hard scene (``--scenes 1``); paper's photos and the baseline all the same.

The baseline is the code of commit ``BASELINE`` (before the recognizer charged dropped corners
by the area they change), extracted with ``git archive`` and run in a subprocess from the
same virtualenv.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from bench_fly import extract  # run as a script: its folder is on sys.path

BASELINE = "73c3162"

# Runs with the code to measure on sys.path; prints one JSON object. Only APIs both have.
_WORKER = """
import json, math, sys
import numpy as np
from uavtool.camera import CameraPose, Intrinsics
from uavtool.images import png_decode
from uavtool.mission.analysis import judge, nadir_shapes, target_shapes
from uavtool.mission.params import Params
from uavtool.runner.fly import target_picture
from uavtool.world import load_scene, render
from uavtool.world.hard import generate_hard_scene

K = Intrinsics.from_hfov()
P = Params()
first, n = int(sys.argv[1]), int(sys.argv[2])


def box(building):
    pts = np.array([xy for blk in building.blocks for xy in blk.footprint_enu_m])
    centre = (pts.min(0) + pts.max(0)) / 2.0
    top = max(blk.top_m for blk in building.blocks)
    return centre, top, float(np.max(pts.max(0) - pts.min(0)))


def score(scene, ref, pose):
    j = judge(P, ref, nadir_shapes(P, render(scene, pose, K)), K)
    return j.score if j.judgeable else None


def sweep(scene, poses):
    _, ref = target_shapes(P, png_decode(target_picture(scene, K)))
    return [s for s in (score(scene, ref, pose) for pose in poses) if s is not None]


out = {}
paper = load_scene("paper")
(cx, cy), top, _ = box(paper.target_building)
out["paper"] = sweep(
    paper,
    [
        CameraPose((cx + 1.3, cy - 0.7, top + d), float(h), -90.0)
        for d in (15.0, 22.0, 30.0, 40.0)
        for h in range(360)
    ],
)
hard = []
half_v = math.radians(Intrinsics.from_hfov().vfov_deg) / 2.0
for seed in range(first, first + n):
    scene = generate_hard_scene(seed=seed)
    (cx, cy), top, span = box(scene.target_building)
    hard += sweep(
        scene,
        [
            CameraPose((cx, cy, top + span / fill / (2.0 * math.tan(half_v))), h + 0.37 * k, -90.0)
            for k, fill in enumerate((0.35, 0.5, 0.7))
            for h in range(0, 360, 10)
        ],
    )
out["hard"] = hard
# Every other building of each scene, where a look at it would be taken from (50 %) and
# closer (70 %), every 30°: what it scores, and whether the mission would take it.
others, taken = [], 0
for seed in range(first, first + n):
    scene = generate_hard_scene(seed=seed)
    _, ref = target_shapes(P, png_decode(target_picture(scene, K)))
    for building in scene.buildings:
        if building is scene.target_building:
            continue
        (cx, cy), top, span = box(building)
        for k, fill in enumerate((0.5, 0.7)):
            alt = top + span / fill / (2.0 * math.tan(half_v))
            for h in range(0, 360, 30):
                pose = CameraPose((cx + 0.5, cy - 0.3, alt), h + 0.37 * k, -90.0)
                j = judge(P, ref, nadir_shapes(P, render(scene, pose, K)), K)
                if j.judgeable:
                    others.append(j.score)
                    taken += j.matched
out["others"] = others
out["others_taken"] = taken
print(json.dumps(out))
"""


def _run(pythonpath: Path, first: int, n: int) -> tuple[dict[str, Any], float]:
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", _WORKER, str(first), str(n)],
        check=True,
        capture_output=True,
        text=True,
        env=env,
        cwd=pythonpath,  # "python -c" puts its working directory first on sys.path
    )
    scores: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return scores, time.perf_counter() - t0


def _row(scores: list[float]) -> dict[str, float]:
    return {
        "judged": len(scores),
        "< 0.7": sum(s < 0.7 for s in scores),
        "< 0.8": sum(s < 0.8 for s in scores),
        "< 0.9": sum(s < 0.9 for s in scores),
        "worst": min(scores),
        "mean": sum(scores) / len(scores),
    }


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --scenes 1")
    parser.add_argument("--scenes", type=int, default=60, help="hard scenes (default: 60)")
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--baseline", default=BASELINE, help=f"commit (default: {BASELINE})")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(scenes=1)
    args = parser.parse_args()
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        base_dir = extract(args.baseline, Path(tmp))
        new, t_new = _run(root, args.first_seed, args.scenes)
        base, t_base = _run(base_dir, args.first_seed, args.scenes)
    last = args.first_seed + args.scenes - 1
    print(
        f"recognition against heading: paper (4 distances × 360°) and hard scenes "
        f"{args.first_seed}..{last} (3 distances × 36 headings); new vs {args.baseline}"
    )
    for name in ("paper", "hard"):
        a, b = _row(new[name]), _row(base[name])
        print(f"\n  {name:<8}{'new':>12}{'baseline':>12}{'new/baseline':>14}")
        for key in a:
            fmt = "{:>12.3f}" if key in ("worst", "mean") else "{:>12.0f}"
            ratio = a[key] / b[key] if b[key] else float("nan")
            print(f"  {key:<8}" + fmt.format(a[key]) + fmt.format(b[key]) + f"{ratio:>13.2f}x")
    print("\n  other buildings    new    baseline  new/baseline")
    for key, a, b in (
        ("judged", len(new["others"]), len(base["others"])),
        ("taken (false)", new["others_taken"], base["others_taken"]),
        (
            "mean score",
            sum(new["others"]) / len(new["others"]),
            sum(base["others"]) / len(base["others"]),
        ),
    ):
        ratio = a / b if b else float("nan")
        fmt = "{:>10.3f}{:>12.3f}" if key == "mean score" else "{:>10.0f}{:>12.0f}"
        print(f"  {key:<14}" + fmt.format(a, b) + f"{ratio:>13.2f}x")
    print(f"\n  wall time: new {t_new:.0f} s, baseline {t_base:.0f} s")


if __name__ == "__main__":
    main()
