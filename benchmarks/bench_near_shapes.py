"""Near shapes against true shapes: how often the recognizer takes a building that is *almost*
the target for the target, and how often it knows the target itself (issue 45, item 3).

Each pair is a reference, the target picture as ``uavtool scene target`` makes it (the roof
from straight above, north up, 12 px/m, flat colour on grey), and a candidate photographed as
a look photo shows a roof: turned any way, 8-18 px/m, up to 20° off nadir (the roof plane
seen through a pinhole of a 640 px, 60° camera, tilted about a random axis), with sensor
noise (Gaussian, σ 3 DN). Both go through the mission's own ``vectorize`` and
``match_shapes``; the candidate's shape is its largest region of the roof's colour (none
found: score 0).

- **True pairs**: the candidate is the reference's own footprint (rectangles of aspect
  0.45-0.9, L, T and U shapes, 6-18 m).
- **Near pairs**, a class each: the aspect 10 % off; a trapezoid whose top is 60-95 % of its
  base; one corner chamfered (45°, 15-30 % of the shorter edge); one corner notched (a square
  15-30 % of the shorter edge); one arm of an L, T or U 15 % shorter.

Printed: the recognizer's false-match rate per near class and in all, and its true-match
rate, with the outline check the mission makes (`uavtool.vision.verify.outline_fits`), each
against its goal (false ≤ 0.1 %, true ≥ 99.5 %): at the corners' threshold the mission flies
with (`uavtool.mission.Params().recognize.threshold`, 0.7) and at the matcher's own default
(`RecognizeParams.threshold`, 0.8); then the corners alone at the matcher's; and the ROC of
both (true-match rate against false-match rate as the threshold moves, the mission's marked)
as a PNG. Pairs are seeded (``--seed``) and scored on
``--workers`` processes; the figures do not depend on their number.

    python benchmarks/bench_near_shapes.py [--quick] [--pairs 10000] [--seed 45]
        [--workers 2] [--png ROC.png]

``--quick``: 500 pairs of each kind.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import Polygon

from uavtool.mission.params import MissionParams, Params
from uavtool.vision import RecognizeParams, Shape, VectorizeParams, match_shapes, vectorize
from uavtool.vision.align import Match
from uavtool.vision.verify import outline_accuracy_px, outline_fits, outline_gap
from uavtool.world.raster import paint_polygon

ROOF = (210, 40, 40)
GROUND = (128, 128, 128)
FOCAL_PX = 320.0 / math.tan(math.radians(30.0))  # 640 px across 60°
REFERENCE_PX_PER_M = FOCAL_PX / 30.0  # `uavtool scene target`: 30 m above the roof
LOOK_FILL = MissionParams().look_fill
ACCURACY_SEED = 7
NOISE_DN = 3.0
NEAR_CLASSES = ("aspect", "trapezoid", "chamfer", "notch", "arm")
GOAL_FALSE, GOAL_TRUE = 0.001, 0.995


# --- footprints (metres, north up) ----------------------------------------------------------


def _rect(w: float, h: float) -> Polygon:
    return Polygon([(0, 0), (w, 0), (w, h), (0, h)])


def _base(rng: np.random.Generator, kind: str) -> tuple[Polygon, dict[str, float]]:
    """A footprint of ``kind`` and the numbers it was made from."""
    size = rng.uniform(6.0, 18.0)
    if kind == "rect":
        aspect = rng.uniform(0.45, 0.9)
        return _rect(size, size * aspect), {"w": size, "h": size * aspect}
    arm = rng.uniform(0.3, 0.45) * size  # arm width
    if kind == "L":
        a, b = size, rng.uniform(0.6, 1.0) * size
        return _l(a, b, arm), {"a": a, "b": b, "arm": arm}
    if kind == "T":
        a, b = size, rng.uniform(0.6, 1.0) * size
        return _t(a, b, arm), {"a": a, "b": b, "arm": arm}
    a, b = size, rng.uniform(0.6, 1.0) * size
    return _u(a, b, b, arm), {"a": a, "b": b, "arm": arm}


def _l(a: float, b: float, arm: float) -> Polygon:
    return Polygon([(0, 0), (a, 0), (a, arm), (arm, arm), (arm, b), (0, b)])


def _t(a: float, b: float, arm: float) -> Polygon:
    """A bar ``a`` long, its stem ``b`` long from the bar's middle."""
    x0 = (a - arm) / 2
    return Polygon(
        [(0, b - arm), (x0, b - arm), (x0, 0), (x0 + arm, 0), (x0 + arm, b - arm), (a, b - arm),
         (a, b), (0, b)]
    )  # fmt: skip


def _u(a: float, left: float, right: float, arm: float) -> Polygon:
    return Polygon(
        [(0, 0), (a, 0), (a, right), (a - arm, right), (a - arm, arm), (arm, arm), (arm, left),
         (0, left)]
    )  # fmt: skip


def _near(
    rng: np.random.Generator, near: str, kind: str, shape: Polygon, nums: dict[str, float]
) -> Polygon:
    """``shape`` made into a near shape of class ``near``."""
    if near == "aspect":
        factor = 1.1 if rng.random() < 0.5 else 1 / 1.1
        return affinity.scale(shape, xfact=factor, yfact=1.0, origin=(0, 0))
    if near == "trapezoid":
        w, h = nums["w"], nums["h"]
        inset = (1.0 - rng.uniform(0.60, 0.95)) * w / 2
        return Polygon([(0, 0), (w, 0), (w - inset, h), (inset, h)])
    if near in ("chamfer", "notch"):
        minx, miny, maxx, maxy = shape.bounds
        short = min(maxx - minx, maxy - miny) if kind == "rect" else nums["arm"]
        cut = rng.uniform(0.15, 0.30) * short
        corners = [p for p in shape.exterior.coords[:-1] if _convex(shape, p)]
        cx, cy = corners[int(rng.integers(len(corners)))]
        pieces = []
        for sx, sy in ((1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)):
            if near == "chamfer":
                piece = Polygon([(cx, cy), (cx + sx * cut, cy), (cx, cy + sy * cut)])
            else:
                piece = Polygon(
                    [(cx, cy), (cx + sx * cut, cy), (cx + sx * cut, cy + sy * cut),
                     (cx, cy + sy * cut)]
                )  # fmt: skip
            pieces.append((shapely.intersection(piece, shape).area, piece))
        # the quarter the corner's inside is in: the piece the shape holds most of
        piece = max(pieces, key=lambda t: t[0])[1]
        cut_shape = shapely.difference(shape, piece).simplify(1e-6)
        assert cut_shape.area < shape.area - 0.4 * piece.area, "the corner was not cut"
        return cut_shape
    # an arm 15 % shorter
    a, b, arm = nums["a"], nums["b"], nums["arm"]
    if kind == "L":
        return (
            _l(a, arm + (b - arm) * 0.85, arm)
            if rng.random() < 0.5
            else _l(arm + (a - arm) * 0.85, b, arm)
        )
    if kind == "T":
        return _t(a, arm + (b - arm) * 0.85, arm)
    return _u(a, b, arm + (b - arm) * 0.85, arm)


def _convex(shape: Polygon, p: tuple[float, float]) -> bool:
    """Whether the corner at ``p`` points out of ``shape`` (a small square there is mostly
    outside)."""
    probe = shapely.Point(p).buffer(1e-3, quad_segs=2)
    return bool(shapely.intersection(probe, shape).area < 0.5 * probe.area)


# --- pictures -------------------------------------------------------------------------------


def _picture(
    footprint: Polygon,
    px_per_m: float,
    turn_deg: float,
    tilt_deg: float,
    tilt_axis_deg: float,
    rng: np.random.Generator | None,
) -> np.ndarray:
    """``footprint`` drawn as a roof on grey: turned, scaled, seen ``tilt_deg`` off nadir."""
    c = footprint.centroid
    pts = np.asarray(footprint.exterior.coords[:-1], dtype=np.float64) - (c.x, c.y)
    t = math.radians(turn_deg)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    pts = pts @ rot.T * px_per_m
    pts[:, 1] = -pts[:, 1]  # image rows grow southward
    if tilt_deg:
        # the roof plane seen by a pinhole aimed at its centre, tilted about an axis in the
        # image: along the tilt it is foreshortened (cos) and its far side shrinks (the
        # perspective division); across it only the division
        axis = math.radians(tilt_axis_deg)
        u, v = math.cos(axis), math.sin(axis)
        along = pts[:, 0] * u + pts[:, 1] * v
        across = -pts[:, 0] * v + pts[:, 1] * u
        tilt = math.radians(tilt_deg)
        w = 1.0 + along * math.sin(tilt) / FOCAL_PX
        along, across = along * math.cos(tilt) / w, across / w
        pts = np.stack([along * u - across * v, along * v + across * u], axis=1)
    half = _half(pts)
    pts += half
    image = np.empty((2 * half, 2 * half, 3), np.uint8)
    image[:] = GROUND
    paint_polygon(image, pts, ROOF)
    if rng is not None and NOISE_DN:
        noisy = image.astype(np.float64) + rng.normal(0.0, NOISE_DN, image.shape)
        image = np.clip(np.round(noisy), 0, 255).astype(np.uint8)
    return image


def _half(pts: np.ndarray) -> int:
    """Half the side of the square picture ``pts`` (centred on 0) are drawn in."""
    return int(float(np.abs(pts).max()) + 40)


def _rectified(shape: Shape, half: int, tilt_deg: float, tilt_axis_deg: float) -> Shape:
    """``shape`` with the perspective of `_picture`'s tilt undone: the roof's outline as a
    camera square to it would draw it (what a mission does with its photo's pose)."""
    if not tilt_deg:
        return shape
    pts = np.asarray(shape.polygon_px, dtype=np.float64) - half
    axis = math.radians(tilt_axis_deg)
    u, v = math.cos(axis), math.sin(axis)
    along = pts[:, 0] * u + pts[:, 1] * v
    across = -pts[:, 0] * v + pts[:, 1] * u
    tilt = math.radians(tilt_deg)
    along = along / (math.cos(tilt) - along * math.sin(tilt) / FOCAL_PX)
    across = across * (1.0 + along * math.sin(tilt) / FOCAL_PX)
    flat = np.stack([along * u - across * v, along * v + across * u], axis=1) + half
    return Shape.from_rings(
        colour_rgb=shape.colour_rgb,
        polygon_px=flat,
        detail_px=shape.detail_px,
        left_out_px=shape.left_out_px,
    )


def _roof(image: np.ndarray) -> Shape | None:
    shapes = [s for s in vectorize(image, VectorizeParams()) if _near_roof(s.colour_rgb)]
    return max(shapes, key=lambda s: s.area_px) if shapes else None


def _near_roof(rgb: tuple[int, int, int]) -> bool:
    return sum(abs(a - b) for a, b in zip(rgb, ROOF, strict=True)) < 60


# --- pairs ----------------------------------------------------------------------------------


def _pair(seed: int, index: int, near: str | None) -> tuple[str, str, float, bool, float]:
    """(kind, class, score, whether the outline fits, tilt) of pair ``index``: a true pair when
    ``near`` is None."""
    rng = np.random.default_rng([seed, index, 0 if near is None else 1 + NEAR_CLASSES.index(near)])
    kinds = {"aspect": ("rect", "L", "T"), "trapezoid": ("rect",), "chamfer": ("rect", "L"),
             "notch": ("rect", "L"), "arm": ("L", "T", "U")}  # fmt: skip
    kind = str(rng.choice(kinds[near] if near else ("rect", "L", "T", "U")))
    reference, nums = _base(rng, kind)
    candidate = reference if near is None else _near(rng, near, kind, reference, nums)
    ref_shape = _roof(_picture(reference, REFERENCE_PX_PER_M, 0.0, 0.0, 0.0, None))
    tilt, axis = rng.uniform(0.0, 20.0), rng.uniform(0.0, 360.0)
    photo = _picture(
        candidate, _look_px_per_m(rng, candidate), rng.uniform(0.0, 360.0), tilt, axis, rng
    )
    cand_shape = _roof(photo)
    if ref_shape is None or cand_shape is None:
        return kind, near or "true", 0.0, False, tilt
    m = match_shapes(ref_shape, cand_shape, RecognizeParams())
    flat = _rectified(cand_shape, photo.shape[0] // 2, tilt, axis)
    return kind, near or "true", m.score, outline_fits(ref_shape, flat, m), tilt


def _look_px_per_m(rng: np.random.Generator, footprint: Polygon) -> float:
    """A look's scale: the mission flies where the footprint's longest extent spans
    ``look_fill`` of the photo's 480 rows, for the roof height it assumes; a roof lower than
    assumed (up to half the distance) shows smaller."""
    pts = np.asarray(footprint.exterior.coords[:-1])
    extent = max(math.dist(a, b) for a in pts for b in pts)
    return LOOK_FILL * 480.0 / extent * rng.uniform(0.6, 1.0)


def _accuracy_one(index: int) -> tuple[float, float]:
    """(how far the vectorized outline lies from the true one, put on it at unit area, in
    pixels of the picture; the shape's sqrt(area) in pixels) for one drawn footprint."""
    rng = np.random.default_rng([ACCURACY_SEED, index])
    footprint, _ = _base(rng, str(rng.choice(("rect", "L", "T", "U"))))
    image, truth_px = _drawn(footprint, rng.uniform(4.0, 40.0), rng.uniform(0.0, 360.0), rng)
    shape = _roof(image)
    if shape is None:
        return math.inf, 0.0
    truth = Shape.from_rings(colour_rgb=ROOF, polygon_px=truth_px)
    same = Match(1.0, 0.0, (), 0.0, 1.0, False)  # drawn unturned: the gap's search refines
    size = math.sqrt(shape.area_px)
    return outline_gap(truth, shape, same) * size, size


def _drawn(
    footprint: Polygon, px_per_m: float, turn_deg: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """`_picture` without tilt, and the true outline in the picture's pixels (the fill's
    sub-pixel vertices, shifted by a random fraction of a pixel)."""
    c = footprint.centroid
    pts = np.asarray(footprint.exterior.coords[:-1], dtype=np.float64) - (c.x, c.y)
    t = math.radians(turn_deg)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    pts = pts @ rot.T * px_per_m
    pts[:, 1] = -pts[:, 1]
    half = _half(pts)
    pts += half + rng.uniform(0.0, 1.0, 2)
    image = np.empty((2 * half + 2, 2 * half + 2, 3), np.uint8)
    image[:] = GROUND
    paint_polygon(image, pts, ROOF)
    noisy = image.astype(np.float64) + rng.normal(0.0, NOISE_DN, image.shape)
    return np.clip(np.round(noisy), 0, 255).astype(np.uint8), pts


def accuracy(n: int, workers: int) -> None:
    """The vectorizer's outline accuracy, measured, against `outline_accuracy_px`."""
    with ProcessPoolExecutor(workers) as pool:
        rows = list(pool.map(_accuracy_one, range(n), chunksize=50))
    gaps = np.array([g for g, _ in rows])
    bound = outline_accuracy_px(VectorizeParams())
    print(f"outline accuracy: {n} footprints (rect, L, T, U), 4-40 px/m, any turn, σ {NOISE_DN} DN")
    print(
        f"  from the true outline at unit area: median {np.median(gaps):.2f} px, 99th "
        f"percentile {np.percentile(gaps, 99):.2f} px, 99.9th {np.percentile(gaps, 99.9):.2f} "
        f"px, worst {gaps.max():.2f} px"
    )
    met = np.mean(gaps <= bound) * 100
    print(f"  outline_accuracy_px (defaults) {bound:.2f} px: met by {met:.2f} % of outlines")
    for lo, hi in ((0, 100), (100, 200), (200, 400), (400, 10**6)):
        part = np.array([g for g, size in rows if lo <= size < hi])
        if len(part):
            print(
                f"    {lo:>4}-{hi if hi < 10**6 else '':<4} px across: {len(part):>5}, "
                f"99th percentile {np.percentile(part, 99):.2f} px, worst {part.max():.2f} px, "
                f"within the bound {np.mean(part <= bound) * 100:.1f} %"
            )


def _chunk(
    args: tuple[int, list[tuple[int, str | None]]],
) -> list[tuple[str, str, float, bool, float]]:
    seed, jobs = args
    return [_pair(seed, i, near) for i, near in jobs]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="500 pairs of each kind")
    parser.add_argument("--pairs", type=int, default=10_000, help="of each kind (true, near)")
    parser.add_argument("--seed", type=int, default=45)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--png",
        type=Path,
        default=Path(tempfile.gettempdir()) / "near_shapes_roc.png",
        help="where the ROC goes (default: %(default)s)",
    )
    parser.add_argument(
        "--accuracy", action="store_true", help="instead: measure the vectorizer's accuracy"
    )
    args = parser.parse_args()
    n = 500 if args.quick else args.pairs
    if args.accuracy:
        accuracy(n, args.workers)
        return
    jobs: list[tuple[int, str | None]] = [(i, None) for i in range(n)]
    jobs += [(i, NEAR_CLASSES[i % len(NEAR_CLASSES)]) for i in range(n)]
    chunks = [(args.seed, jobs[k : k + 200]) for k in range(0, len(jobs), 200)]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = [row for part in pool.map(_chunk, chunks) for row in part]
    took = time.perf_counter() - t0
    threshold = RecognizeParams().threshold
    print(f"near shapes vs true shapes: {n} pairs of each, seed {args.seed}, {took:.0f} s")
    # the recognizer's whole verdict: a pair whose outline does not fit is no match at any
    # threshold (its score counts as 0); at the threshold the mission flies with, and at the
    # matcher's own
    true = np.array([r[2] if r[3] else 0.0 for r in rows if r[1] == "true"])
    near = np.array([r[2] if r[3] else 0.0 for r in rows if r[1] != "true"])
    flown = Params().recognize.threshold
    for label, cut in (("the mission's", flown), ("the matcher's", threshold)):
        _verdict(rows, true, near, cut, label)
    corners_true = np.array([r[2] for r in rows if r[1] == "true"])
    corners_near = np.array([r[2] for r in rows if r[1] != "true"])
    print(f"  the corners alone at the threshold {threshold}: true matches "
          f"{float((corners_true >= threshold).mean()) * 100:.2f} %, false matches "
          f"{float((corners_near >= threshold).mean()) * 100:.2f} %")  # fmt: skip
    for cls in NEAR_CLASSES:
        scores = np.array([r[2] for r in rows if r[1] == cls])
        by_kind = {
            k: float(
                (np.array([r[2] for r in rows if r[1] == cls and r[0] == k]) >= threshold).mean()
            )
            for k in sorted({r[0] for r in rows if r[1] == cls})
        }
        kinds = ", ".join(f"{k} {v * 100:.1f} %" for k, v in by_kind.items())
        print(f"      {cls:<10} {float((scores >= threshold).mean()) * 100:7.2f} %  "
              f"(median score {np.median(scores):.3f}; {kinds})")  # fmt: skip
    for kind in ("rect", "L", "T", "U"):
        scores = np.array([r[2] for r in rows if r[1] == "true" and r[0] == kind])
        print(f"      true {kind:<5} {float((scores >= threshold).mean()) * 100:7.2f} %  "
              f"(5th percentile score {np.percentile(scores, 5):.3f})")  # fmt: skip
    # the best a threshold alone could do: the lowest false-match rate keeping the true goal
    cut = float(np.quantile(corners_true, 1.0 - GOAL_TRUE))
    print(
        f"    any threshold on the corners alone: keeping {GOAL_TRUE * 100:.1f} % true matches "
        f"(threshold {cut:.3f}) lets {float((corners_near >= cut).mean()) * 100:.2f} % of near "
        "shapes through"
    )
    _roc({"the recognizer": (true, near), "the corners alone": (corners_true, corners_near)},
         flown, args.png)  # fmt: skip
    print(f"  ROC: {args.png}")


def _verdict(
    rows: list[tuple[str, str, float, bool, float]],
    true: np.ndarray,
    near: np.ndarray,
    threshold: float,
    label: str,
) -> None:
    """The recognizer's true- and false-match rates at ``threshold`` (``true``, ``near``: its
    scores of the true and the near pairs, 0 where the outline does not fit), against the
    goals, and per near class."""
    print(f"  the recognizer at {label} threshold: corners at {threshold} and the outline "
          "within the photos' accuracy (`uavtool.vision.verify`)")  # fmt: skip
    tmr = float((true >= threshold).mean())
    goal = f"goal >= {GOAL_TRUE * 100:.1f} %"
    print(f"    true matches   {tmr * 100:7.2f} %  ({goal}): {_met(tmr >= GOAL_TRUE)}")
    fmr = float((near >= threshold).mean())
    goal = f"goal <= {GOAL_FALSE * 100:.1f} %"
    print(f"    false matches  {fmr * 100:7.2f} %  ({goal}): {_met(fmr <= GOAL_FALSE)}")
    _outline_check(rows, threshold)


def _outline_check(rows: list[tuple[str, str, float, bool, float]], threshold: float) -> None:
    """The recognizer's verdict per near class, in all and for the pairs seen within 3° of
    nadir (a look photo's view; the outline check assumes the roof's plane faces the camera
    and undoes no perspective)."""
    for label, keep in (("all", 90.0), ("within 3° of nadir", 3.0)):
        kept = [r for r in rows if r[4] <= keep]
        true = [r[2] >= threshold and r[3] for r in kept if r[1] == "true"]
        line = f"    {label:<19} true matches {np.mean(true) * 100:6.2f} % ({len(true)})"
        for cls in NEAR_CLASSES:
            near = [r[2] >= threshold and r[3] for r in kept if r[1] == cls]
            line += f", {cls} {np.mean(near) * 100:.2f} %"
        near_all = [r[2] >= threshold and r[3] for r in kept if r[1] != "true"]
        print(line + f"; false matches {np.mean(near_all) * 100:.2f} % ({len(near_all)})")


def _met(ok: bool) -> str:
    return "met" if ok else "NOT met"


def _roc(curves: dict[str, tuple[np.ndarray, np.ndarray]], threshold: float, png: Path) -> None:
    """True-match rate against false-match rate as the threshold moves, one curve per
    (true scores, near scores); a rate of 0 is drawn at 1e-5 (the log axis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cuts = np.linspace(0.0, 1.0, 401)
    fig, ax = plt.subplots(figsize=(6, 4.5), dpi=100)
    colours = ("tab:blue", "tab:orange")
    for (label, (true, near)), colour in zip(curves.items(), colours, strict=True):
        tmr = [(true >= c).mean() for c in cuts]
        fmr = [max((near >= c).mean(), 1e-5) for c in cuts]
        ax.plot(fmr, tmr, color=colour, label=f"{label}, the threshold moving from 0 to 1")
        at = ((near >= threshold).mean(), (true >= threshold).mean())
        ax.plot([max(at[0], 1e-5)], [at[1]], "o", color=colour)
    ax.plot([], [], "o", color="grey", label=f"at the threshold {threshold}")
    ax.axvline(GOAL_FALSE, color="grey", ls="--", lw=0.8)
    ax.axhline(GOAL_TRUE, color="grey", ls="--", lw=0.8, label="goals")
    ax.set_xscale("log")
    ax.set_xlim(1e-5, 1.0)
    ax.set_ylim(0.0, 1.01)
    ax.set_xlabel("false-match rate (near shapes taken for the target)")
    ax.set_ylabel("true-match rate")
    ax.set_title(f"near vs true shapes, {len(next(iter(curves.values()))[0])} pairs each")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(png)
    plt.close(fig)


if __name__ == "__main__":
    main()
