"""3D model quality: volumetric IoU of the model against the true building mesh.

Seeded buildings (rectangles, L, T, U; 5–12 m, 3–9 m high, any rotation), about half with
a ground-level through-hole along one axis, each alone in a scene. Top photo from 20 m over
the footprint centre (random heading), front and right photos (pitch 0, 3 m up) from the
footprint's south and east sides at a distance that fits the building in the frame, like
the mission's viewpoints. A through-hole is reproduced when the tunnel's centre is empty
in the model.

    python benchmarks/bench_vision_model.py [--quick] [--buildings 60]

``--quick``: four buildings (``--buildings 4``: one of each shape, two with a through-hole).
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time

import manifold3d
import numpy as np

from uavtool.camera import CameraPose, Intrinsics
from uavtool.vision import VectorizeParams, vectorize
from uavtool.vision.errors import ModelInputError
from uavtool.vision.model3d import View, build_model, same_colour
from uavtool.world import building_mesh, render, scene_from_dict

K = Intrinsics.from_hfov()
COLOUR = (210, 40, 40)


def _rects(kind: str, w: float, d: float, t: float) -> list[tuple[float, float, float, float]]:
    """Axis-aligned rectangles (x0, y0, x1, y1) whose union is the footprint."""
    if kind == "rect":
        return [(0, 0, w, d)]
    if kind == "L":
        return [(0, 0, w, t), (0, t, t, d)]
    if kind == "T":
        a = (w - t) / 2
        return [(0, d - t, w, d), (a, 0, a + t, d - t)]
    return [(0, 0, w, t), (0, t, t, d), (w - t, t, w, d)]  # U


def building(seed: int) -> tuple[dict, tuple[float, float, float] | None, float]:
    """A scene dict with one building, the tunnel centre (local, before rotation) or None."""
    rng = random.Random(seed)
    kind = ("rect", "L", "T", "U")[seed % 4]
    w, d = 5 + 7 * rng.random(), 5 + 7 * rng.random()
    t = min(w, d) * (0.35 + 0.15 * rng.random())
    h = 3 + 6 * rng.random()
    rects = _rects(kind, w, d, t)
    tunnel = None
    blocks = []
    if seed % 2 == 0:
        # A tunnel through the first rectangle along y, where nothing stands in front of or
        # behind it (so the front photo sees through), over 60 % of that free stretch.
        x0, y0, x1, y1 = rects[0]
        lo, hi = {"rect": (0, w), "L": (t, w), "T": (0, (w - t) / 2), "U": (t, w - t)}[kind]
        a, tw = lo + 0.2 * (hi - lo), 0.6 * (hi - lo)
        th = min(2.5, 0.5 * h)
        rects = [(x0, y0, a, y1), (a + tw, y0, x1, y1), *rects[1:]]
        blocks.append(((a, y0, a + tw, y1), th))
        tunnel = (a + tw / 2, (y0 + y1) / 2, th / 2)
    angle = rng.random() * 360.0
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))

    def rot(x: float, y: float) -> list[float]:
        x, y = x - w / 2, y - d / 2
        return [c * x - s * y, s * x + c * y]

    def fp(r: tuple[float, float, float, float]) -> list[list[float]]:
        x0, y0, x1, y1 = r
        return [rot(x0, y0), rot(x1, y0), rot(x1, y1), rot(x0, y1)]

    out = [{"footprint": fp(r), "top_m": h} for r in rects]
    out += [{"footprint": fp(r), "base_m": base, "top_m": h} for r, base in blocks]
    doc = {
        "version": 1,
        "name": f"model-{seed}",
        "origin": {"lat_deg": 50.0, "lon_deg": 20.0, "alt_amsl_m": 200.0, "heading_deg": 0.0},
        "target": "b",
        "buildings": [{"name": "b", "color": list(COLOUR), "blocks": out}],
    }
    if tunnel is not None:
        tunnel = (*rot(tunnel[0], tunnel[1]), tunnel[2])
    return doc, tunnel, angle


def _manifold(mesh) -> manifold3d.Manifold:
    return manifold3d.Manifold(
        manifold3d.Mesh(
            vert_properties=np.asarray(mesh.vertices, np.float32),
            tri_verts=np.asarray(mesh.faces, np.uint32),
        )
    )


def run(count: int) -> None:
    seeds = list(range(count))
    ious, holes, times, failures = [], [0, 0], [], []
    nadir = VectorizeParams(roof_only=True)
    for seed in seeds:
        doc, tunnel, angle = building(seed)
        scene = scene_from_dict(doc, source=doc["name"])
        truth = building_mesh(scene.buildings[0])
        (x0, y0, _), (x1, y1, top) = truth.bounds
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        # Front and right photos face the building's own sides (as the mission's viewpoints
        # do: sides of the smallest enclosing rectangle), far enough that the larger of
        # width / height fills ~70 % of the frame.
        span = max(x1 - x0, y1 - y0, 2 * top)
        dist = span / 0.7 / (2 * math.tan(math.radians(K.hfov_deg / 2))) + span / 2
        a = math.radians(angle)
        fwd = (-math.sin(a), math.cos(a))  # the building's local +y (front camera looks along)
        side = (math.cos(a), math.sin(a))  # local +x: the right camera sits there, looking back
        rng = random.Random(seed + 99)
        poses = {
            "top": CameraPose((cx, cy, 20.0 + top), rng.random() * 360, -90.0),
            "front": CameraPose((cx - dist * fwd[0], cy - dist * fwd[1], top / 2), -angle, 0.0),
            "right": CameraPose(
                (cx + dist * side[0], cy + dist * side[1], top / 2),
                math.degrees(math.atan2(-side[0], -side[1])),
                0.0,
            ),
        }
        views = {}
        for name, pose in poses.items():
            frame = render(scene, pose, K, noise_seed=seed)
            shapes = vectorize(frame, nadir if name == "top" else None)
            views[name] = View(same_colour(shapes, COLOUR, hue_tolerance_deg=15), pose, K)
        t = time.perf_counter()
        try:
            model = build_model(views["top"], views["front"], views["right"])
        except ModelInputError as exc:
            failures.append((seed, str(exc)))
            continue
        times.append(time.perf_counter() - t)
        a, b = _manifold(model.mesh), _manifold(truth)
        inter = (a ^ b).volume()
        ious.append(inter / (a.volume() + b.volume() - inter))
        if tunnel is not None:
            probe = manifold3d.Manifold.cube((0.2, 0.2, 0.2), center=True).translate(tunnel)
            holes[1] += 1
            holes[0] += (a ^ probe).volume() < 1e-6
    print(
        f"seeds 0..{count - 1}: {len(ious)} models ({count} buildings: rect/L/T/U in turn, "
        f"a through-hole in every second), {len(failures)} refused"
    )
    print(
        f"IoU median {statistics.median(ious):.3f}, worst {min(ious):.3f}, "
        f"mean {statistics.fmean(ious):.3f}, 10th percentile "
        f"{sorted(ious)[len(ious) // 10]:.3f}"
    )
    print(f"through-holes reproduced: {holes[0]}/{holes[1]} = {100 * holes[0] / holes[1]:.0f}%")
    print(
        f"build time median {1e3 * statistics.median(times):.1f} ms, max {1e3 * max(times):.1f} ms"
    )
    for seed, msg in failures:
        print(f"  refused seed {seed}: {msg}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="the smallest run: --buildings 4")
    ap.add_argument("--buildings", type=int, default=60, help="default: %(default)s")
    if ap.parse_known_args()[0].quick:
        ap.set_defaults(buildings=4)
    run(ap.parse_args().buildings)
