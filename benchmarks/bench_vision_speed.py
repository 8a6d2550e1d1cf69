"""Vision speed on the paper scene, each next to its baseline, medians in one run.

Each figure is the median wall time, the functions compared taking turns in every round;
in brackets the median CPU time of this thread, which other processes on a busy machine
inflate much less.

* vectorize the 640×480 overview frame (45 m above home, noise seed 1) vs OpenCV's own
  path per colour (HSV, ``inRange``, ``findContours``, ``approxPolyDP``);
* match two shapes (the red target's outline against the red building's in the frame);
* build the red target's model from its top / front / right photos.

    python benchmarks/bench_vision_speed.py [--quick] [--repeat 200]

``--quick``: medians of 5 rounds (``--repeat 5``).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import cv2

from uavtool.camera import CameraPose, Intrinsics
from uavtool.vision import VectorizeParams, match_shapes, vectorize
from uavtool.vision.model3d import View, build_model, same_colour
from uavtool.world import load_scene, render

K = Intrinsics.from_hfov()


class Timing(float):
    """A median wall time in ms (the float) with the median thread CPU time beside it."""

    cpu_ms: float

    def __str__(self) -> str:
        return f"{float(self):.3g} ms [cpu {self.cpu_ms:.3g}]"


def median_ms(fn: Callable[[], object], repeat: int) -> Timing:
    return side_by_side([fn], repeat)[0]


def side_by_side(fns: list[Callable[[], object]], repeat: int) -> list[Timing]:
    """Median times of ``fns``, run in turn in every round, so a machine that changes speed
    during the run (shared cores, frequency scaling) slows them all alike and their ratio
    stays fair."""
    for fn in fns:
        fn()
    wall: list[list[float]] = [[] for _ in fns]
    cpu: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for k, fn in enumerate(fns):
            t, c = time.perf_counter(), time.thread_time()
            fn()
            wall[k].append(time.perf_counter() - t)
            cpu[k].append(time.thread_time() - c)
    out = []
    for w, c in zip(wall, cpu, strict=True):
        timing = Timing(1e3 * statistics.median(w))
        timing.cpu_ms = 1e3 * statistics.median(c)
        out.append(timing)
    return out


def opencv_baseline(frame, colours_hsv) -> list:
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV_FULL)
    out = []
    for lo, hi in colours_hsv:
        mask = cv2.inRange(hsv, lo, hi)
        contours, _ = cv2.findContours(mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
        out.extend(cv2.approxPolyDP(c, 1.5, True) for c in contours)
    return out


def run(repeat: int) -> None:
    cv2.setNumThreads(1)
    scene = load_scene("paper")
    frame = render(scene, CameraPose((0.0, 0.0, 45.0), 0.0, -90.0), K, noise_seed=1)
    shapes = vectorize(frame)
    # The baseline's palette: each shape's hue ± 12°, the same windows ours uses.
    colours = []
    for s in shapes:
        h = int(
            cv2.cvtColor(
                frame[None, None, round(s.centroid_px[1]), round(s.centroid_px[0])],
                cv2.COLOR_RGB2HSV_FULL,
            )[0, 0, 0]
        )
        colours.append(((max(h - 9, 0), 70, 30), (min(h + 9, 255), 255, 255)))
    roof_only = VectorizeParams(roof_only=True)
    ours, roof, base = side_by_side(
        [
            lambda: vectorize(frame),
            lambda: vectorize(frame, roof_only),
            lambda: opencv_baseline(frame, colours),
        ],
        repeat,
    )
    per_colour = base / len(colours)
    print(
        f"vectorize paper overview ({len(shapes)} shapes, {len(colours)} colours): "
        f"{ours} median (roof_only {roof}); OpenCV contour+approxPolyDP "
        f"{base} = {per_colour:.2f} ms per colour; ratio ours/OpenCV {ours / base:.2f}"
    )

    red = scene.building("red").color_rgb
    target = same_colour(
        vectorize(
            render(scene, CameraPose((10.0, -8.0, 26.5), 0.0, -90.0), K),
            VectorizeParams(roof_only=True),
        ),
        red,
        hue_tolerance_deg=10,
    )[0]
    cand = same_colour(shapes, red, hue_tolerance_deg=10)[0]
    hu, ms = side_by_side(
        [
            lambda: cv2.matchShapes(
                target.polygon_px.astype("float32"),
                cand.polygon_px.astype("float32"),
                cv2.CONTOURS_MATCH_I1,
                0.0,
            ),
            lambda: match_shapes(target, cand),
        ],
        repeat,
    )
    print(
        f"match two shapes ({len(target.polygon_px)} vs {len(cand.polygon_px)} corners): "
        f"{ms} median; cv2.matchShapes {hu}"
    )

    poses = {
        "top": CameraPose((10.0, -8.0, 20.0), 0.0, -90.0),
        "front": CameraPose((10.0, -27.0, 3.0), 0.0, 0.0),
        "right": CameraPose((30.0, -8.0, 3.0), 270.0, 0.0),
    }
    views = {}
    for name, pose in poses.items():
        p = VectorizeParams(roof_only=name == "top")
        views[name] = View(
            same_colour(
                vectorize(render(scene, pose, K, noise_seed=2), p), red, hue_tolerance_deg=15
            ),
            pose,
            K,
        )
    model = median_ms(
        lambda: build_model(views["top"], views["front"], views["right"]), max(repeat // 10, 5)
    )
    print(f"build the paper target's model: {model} median")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="the smallest run: --repeat 5")
    ap.add_argument("--repeat", type=int, default=200, help="rounds (default: %(default)s)")
    if ap.parse_known_args()[0].quick:
        ap.set_defaults(repeat=5)
    run(ap.parse_args().repeat)
