"""The mission on scenes it has never seen: generated hard scenes (``uavtool.world.hard``:
3–25 m buildings, stepped and arched ones, a mirror decoy of the target in a close hue, a
scaled and turned copy, a near-identical shape, spread past one overview, home beside a
building), each flown on the built-in vehicle by today's mission and by the baseline's.

    python benchmarks/bench_mission_generalization.py [--quick] [--scenes 200] [--first-seed 1]
        [--baseline COMMIT] [--workers 2] [--variants new,baseline] [--random-home] [--town]
        [--world]

``--quick``: two scenes (``--scenes 2``), both variants, every row of the table.

``--town``: scenes the mission was not tuned on (``HardOptions.town()``, as `uavtool scene
random --hard --town`): grey, white, black and grey-blue roofs, darker shades of a hue,
decoys in the target's exact colour that differ by a courtyard or a wing, courtyard and
3–5 m targets, 30–60 m towers, home beside a tower or under a deck, dense blocks. The
report then gets one row per class (scenes holding it: correct / wrong / no match / crashed
/ model built), and the baseline is ``TOWN_BASELINE`` unless ``--baseline`` is given.
Combines with ``--random-home``.

``--world``: town scenes with every world knob on as well (as `uavtool scene random --hard
--town --world`: any light, any ground colour, ground areas, a ground texture, near-shape
decoys of the target's colour, homes anywhere on Earth), with a row per world class too
(`WORLD_CLASSES`: low sun, a saturated ground, near the date line, far north or south). Only
today's mission is flown unless ``--variants`` says otherwise: a baseline from before the
world knobs cannot read such scenes.

The baseline is the code of commit ``BASELINE`` (the mission before roof heights, chosen
altitudes, the mirror rule and collisions: fixed 45/20 m, a 5 m roof plane), with ``--town``
``TOWN_BASELINE`` (675267c, the mission the town issue measures today's against); any
commit with ``--baseline``. It is extracted with ``git archive`` (only when the baseline
variant is flown) and run from the same virtualenv in worker processes beside today's. Every
flight writes its recording; both are judged from their recordings by today's code against
the scene's ground truth, so the figures are comparable:

- correct matches; wrong matches, mirror-decoy matches counted apart; no match;
- models built (of matched scenes), median and worst IoU; tunnels kept (targets with one);
- closest clearance between the vehicle's body and any building (away from the take-off
  column over home, which a building beside home may crowd), crashes (today's vehicle
  crashes for real; for the baseline, whose vehicle flew through walls, a crash is a
  clearance below zero);
- vehicle flight time.

Goals (issue "The mission on scenes it has never seen"): correct ≥ 98 %, no mirror match,
wrong ≤ 0.5 %, a model in ≥ 95 % of matched scenes with median IoU ≥ 0.85, tunnels kept in
≥ 90 %, no crash, clearance never below the safety margin (4 m).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from bench_fly import extract  # run as a script: its folder is on sys.path

from uavtool.recording import JsonDocument, RecordingReader
from uavtool.recording.topics import OBSERVATIONS, OUTPUTS
from uavtool.runner.evaluate import (
    building_under,
    closest_clearance,
    model_iou,
    nearest_building,
    tunnel_kept,
)
from uavtool.sitl import SitlConfig
from uavtool.world import Scene, scene_to_dict
from uavtool.world.hard import (
    TOWN_CLASSES,
    HardOptions,
    HardSceneInfo,
    generate_hard_scene_with_info,
)

ROOT = Path(__file__).resolve().parents[1]
BASELINE = "863e7d7"
TOWN_BASELINE = "675267c"
SAFETY_MARGIN_M = 4.0
HOME_COLUMN_M = 1.5  # route points this close to home (horizontally) are take-off/landing
WORLD_CLASSES = (
    "sun below 20°",
    "ground saturated",
    "ground areas",
    "ground texture",
    "near shapes",
    "home within 10° of ±180°",
    "home beyond 60° latitude",
)
"""The world classes a scene may hold (`world_classes`), each a breakdown row of --world."""
SATURATED = 0.27
"""The HSV saturation from which a ground counts as a colour rather than a grey."""


def _saturation(rgb: tuple[int, int, int]) -> float:
    return (max(rgb) - min(rgb)) / max(*rgb, 1)


def world_classes(scene: Scene, info: HardSceneInfo) -> tuple[str, ...]:
    """The :data:`WORLD_CLASSES` ``scene`` holds, in that order."""
    held = {
        "sun below 20°": scene.lighting.sun_elevation_deg < 20.0,
        "ground saturated": _saturation(scene.ground_rgb) >= SATURATED,
        "ground areas": bool(scene.ground_areas),
        "ground texture": scene.ground_texture is not None,
        "near shapes": bool(info.near_shapes),
        "home within 10° of ±180°": abs(abs(scene.home.lon_deg) - 180.0) <= 10.0,
        "home beyond 60° latitude": abs(scene.home.lat_deg) > 60.0,
    }
    return tuple(c for c in WORLD_CLASSES if held[c])


# Flies each (scene file, recording) pair given as JSON on stdin with the code on sys.path;
# prints one JSON line per flight. Only APIs both versions have.
_WORKER = """
import json, sys, time, traceback
import uavtool
print(json.dumps({"uavtool": uavtool.__file__}), file=sys.stderr)
from pathlib import Path
from uavtool.runner.fly import FlyConfig, fly
for scene, record in json.load(sys.stdin):
    t0 = time.perf_counter()
    try:
        s = fly(FlyConfig(scene=scene, record=Path(record)))
        status = s.outcome.status.value
    except Exception as exc:
        status = "error: " + "".join(traceback.format_exception_only(exc)).strip()
    print(json.dumps({"record": record, "status": status, "wall_s": time.perf_counter() - t0}),
          flush=True)
"""


@dataclass(frozen=True, slots=True)
class Result:
    seed: int
    status: str
    matched: str
    target: str
    mirror: bool
    model: bool
    iou: float | None
    tunnel: bool | None
    clearance_m: float
    crashed: bool
    flight_s: float
    wall_s: float
    classes: tuple[str, ...] = ()  # the town classes the scene holds
    wrong_kind: str = ""  # what the building wrongly matched is (see _kind)
    flew: bool = True  # False: the vehicle never left the ground (a take-off refused)


def _kind(info: HardSceneInfo, name: str) -> str:
    """What a building is to the scene: a decoy of some kind, a darker shade, grey, other."""
    for kind, who in (
        ("mirror decoy", info.mirror_decoy),
        ("near decoy", info.near_decoy),
        ("scaled decoy", info.scaled_decoy),
        ("hole decoy", info.hole_decoy),
        ("wing decoy", info.wing_decoy),
    ):
        if name == who:
            return kind
    for darker, brighter in info.darker:
        if name == darker:
            return "darker shade of the target" if brighter == info.target else "darker shade"
    if name in info.grey:
        return "grey"
    return "other"


def fly_batch(
    pairs: list[tuple[str, str]], pythonpath: Path | None, cwd: Path
) -> list[dict[str, Any]]:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    done = subprocess.run(  # cwd: `python -c` puts it first on sys.path, before PYTHONPATH
        [sys.executable, "-c", _WORKER],
        input=json.dumps(pairs),
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        check=False,
    )
    rows = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode != 0 and len(rows) < len(pairs):
        tail = done.stderr.strip().splitlines()[-1:] or ["?"]
        flown = {r["record"] for r in rows}
        rows += [
            {"record": rec, "status": f"error: worker died: {tail[0]}", "wall_s": 0.0}
            for _, rec in pairs
            if rec not in flown
        ]
    return rows


def judge(seed: int, scene: Scene, info: HardSceneInfo, row: dict[str, Any]) -> Result:
    """One flight's result, judged from its recording against the scene's ground truth."""
    result = _judge(seed, scene, info, row)
    return replace(result, classes=result.classes + world_classes(scene, info))


def _judge(seed: int, scene: Scene, info: HardSceneInfo, row: dict[str, Any]) -> Result:
    path = Path(row["record"])
    status = str(row["status"])
    empty = Result(
        seed,
        status,
        "",
        scene.target,
        False,
        False,
        None,
        None,
        math.inf,
        False,
        0.0,
        float(row["wall_s"]),
        info.classes,
    )
    if status.startswith("error") or not path.exists():
        return empty
    route: list[tuple[float, float, float]] = []
    times: list[int] = []
    plan: Mapping[str, Any] | None = None
    outcome: Mapping[str, Any] = {}
    model: Mapping[str, Any] | None = None
    views: Mapping[str, Any] | None = None
    with RecordingReader(path) as reader:
        for entry in reader.entries([OBSERVATIONS, OUTPUTS]):
            value = entry.value
            if not isinstance(value, JsonDocument):
                continue
            data = value.payload
            kind = data.get("type")
            if kind == "Telemetry" and not data["landed"]:
                x, y, z = data["pos_enu_m"]
                times.append(int(data["time_boot_ms"]))
                if math.hypot(x, y) > HOME_COLUMN_M:
                    route.append((x, y, z))
            elif kind == "Plan":
                plan = data
            elif kind == "ModelBuilt":
                model = data
            elif kind == "Viewpoints":
                views = data
            elif kind == "Outcome":
                outcome = data
    # The building matched is the one the mission went on to photograph from above (a look
    # taken again may have centred on another roof than its point of interest's).
    matched = ""
    poi = int(outcome.get("matched_poi", -1))
    if views is not None:
        # As `uavtool fly` judges it: the building the measured footprint overlaps most (an
        # L's or a U's vertex average may lie in a neighbour, a courtyard's in its yard).
        matched = building_under(scene, [(x, y) for x, y in views["footprint_en_m"]])
    elif plan is not None and poi >= 0:
        matched = nearest_building(scene, tuple(plan["pois"][poi]["pos_en_m"]))
    iou = tunnel = None
    if model is not None:
        iou = model_iou(model["vertices_m"], model["faces"], scene)
        tunnel = tunnel_kept(model["vertices_m"], model["faces"], scene)
    clearance, _ = closest_clearance(route, scene, body_radius_m=SitlConfig().body_radius_m)
    crashed = status == "crashed" or clearance < 0.0
    flew = bool(times)
    flight_s = (times[-1] - times[0]) / 1000.0 if len(times) > 1 else 0.0
    return Result(
        seed,
        status,
        matched,
        scene.target,
        bool(matched) and matched == info.mirror_decoy,
        model is not None,
        iou,
        tunnel,
        clearance,
        crashed,
        flight_s,
        float(row["wall_s"]),
        info.classes,
        _kind(info, matched) if matched and matched != scene.target else "",
        flew,
    )


def summarise(name: str, results: list[Result]) -> dict[str, Any]:
    n = len(results)
    correct = [r for r in results if r.matched and r.matched == r.target]
    wrong = [r for r in results if r.matched and r.matched != r.target]
    mirror = [r for r in wrong if r.mirror]
    models = [r for r in correct if r.model]
    ious = sorted(r.iou for r in models if r.iou is not None)
    tunnels = [r for r in models if r.tunnel is not None]
    clear = [r.clearance_m for r in results if math.isfinite(r.clearance_m)]
    crashes = [r for r in results if r.crashed]
    errors = [r for r in results if r.status.startswith("error")]
    flew = [r for r in results if r.flew]
    return {
        "name": name,
        "n": n,
        "correct": len(correct),
        "wrong": len(wrong),
        "mirror": len(mirror),
        "none": n - len(correct) - len(wrong),
        "models": len(models),
        "iou_median": statistics.median(ious) if ious else float("nan"),
        "iou_worst": ious[0] if ious else float("nan"),
        "tunnels": (sum(bool(r.tunnel) for r in tunnels), len(tunnels)),
        "clearance_min": min(clear, default=math.inf),
        "below_margin": sum(c < SAFETY_MARGIN_M for c in clear),
        "crashes": len(crashes),
        "crashes_hidden": sum(r.status != "crashed" for r in crashes),
        "below_2m": sum(c < 2.0 for c in clear),
        "flew": len(flew),
        "correct_flew": sum(r.matched == r.target for r in flew if r.matched),
        "errors": len(errors),
        "flight_s": statistics.median([r.flight_s for r in results if r.flight_s > 0] or [0.0]),
        "wall_s": sum(r.wall_s for r in results),
        "wrong_seeds": [r.seed for r in wrong],
        "mirror_seeds": [r.seed for r in mirror],
        "none_seeds": [r.seed for r in results if not r.matched],
        "crash_seeds": [r.seed for r in crashes],
        "no_model_seeds": [r.seed for r in correct if not r.model],
        "below_margin_seeds": [r.seed for r in results if r.clearance_m < SAFETY_MARGIN_M],
        "tunnel_lost_seeds": [r.seed for r in tunnels if not r.tunnel],
        "statuses": _count(r.status.split(":")[0] for r in results),
        "wrong_kinds": _count(r.wrong_kind for r in wrong),
        "classes": {
            c: _by_class([r for r in results if c in r.classes])
            for c in TOWN_CLASSES + WORLD_CLASSES
        },
    }


def _by_class(results: list[Result]) -> dict[str, Any]:
    """The breakdown row of the scenes holding one town class."""
    correct = [r for r in results if r.matched and r.matched == r.target]
    return {
        "n": len(results),
        "correct": len(correct),
        "wrong": sum(bool(r.matched) and r.matched != r.target for r in results),
        "none": sum(not r.matched for r in results),
        "crashes": sum(r.crashed for r in results),
        "models": sum(r.model for r in correct),
        "seeds": {
            "wrong": [r.seed for r in results if r.matched and r.matched != r.target],
            "no match": [r.seed for r in results if not r.matched],
            "crashed": [r.seed for r in results if r.crashed],
        },
    }


def _count(items: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for item in items:
        out[item] = out.get(item, 0) + 1
    return dict(sorted(out.items()))


def _pct(k: int, n: int) -> str:
    return f"{k:4d}/{n:<4d} {100.0 * k / n if n else 0.0:5.1f} %"


def report_classes(rows: list[dict[str, Any]], classes: tuple[str, ...] = TOWN_CLASSES) -> None:
    """One row per class: the scenes holding it, and per variant how they went."""
    print(
        "\n  by class: scenes holding it; per variant correct / wrong / no match / "
        "crashed / model built (of correct)"
    )
    print(f"  {'class':<30s}{'scenes':>7s}" + "".join(f"{r['name']:>22s}" for r in rows))
    for c in classes:
        cells = []
        for r in rows:
            k = r["classes"][c]
            cells.append(f"{k['correct']}/{k['wrong']}/{k['none']}/{k['crashes']}/{k['models']}")
        n = rows[0]["classes"][c]["n"]
        print(f"  {c:<30s}{n:>7d}" + "".join(f"{cell:>22s}" for cell in cells))
    for r in rows:
        for c in classes:
            bad = {k: v for k, v in r["classes"][c]["seeds"].items() if v}
            if bad:
                listed = "; ".join(f"{k} {v[:20]}" for k, v in bad.items())
                print(f"    {r['name']}, {c}: {listed}")


def report(rows: list[dict[str, Any]]) -> None:
    def line(label: str, values: list[str]) -> None:
        print(f"  {label:<34s}" + "".join(f"{v:>22s}" for v in values))

    print()
    line("", [r["name"] for r in rows])
    line("correct match", [_pct(r["correct"], r["n"]) for r in rows])
    line("wrong match", [_pct(r["wrong"], r["n"]) for r in rows])
    line("  of which the mirror decoy", [_pct(r["mirror"], r["n"]) for r in rows])
    line("no match", [_pct(r["none"], r["n"]) for r in rows])
    line("  of which never took off", [_pct(r["n"] - r["flew"], r["n"]) for r in rows])
    line("correct, of flights that took off", [_pct(r["correct_flew"], r["flew"]) for r in rows])
    line("model built (of correct matches)", [_pct(r["models"], r["correct"]) for r in rows])
    line("IoU median / worst", [f"{r['iou_median']:.3f} / {r['iou_worst']:.3f}" for r in rows])
    line("tunnels kept", [_pct(*r["tunnels"]) for r in rows])
    line("closest clearance (m)", [f"{r['clearance_min']:.2f}" for r in rows])
    line(
        f"flights below {SAFETY_MARGIN_M:g} m clearance",
        [_pct(r["below_margin"], r["n"]) for r in rows],
    )
    line("flights below 2 m clearance", [_pct(r["below_2m"], r["n"]) for r in rows])
    line("crashes", [_pct(r["crashes"], r["n"]) for r in rows])
    line("  of which not reported as a crash", [_pct(r["crashes_hidden"], r["n"]) for r in rows])
    line("errors (exceptions)", [_pct(r["errors"], r["n"]) for r in rows])
    line("median flight time (s)", [f"{r['flight_s']:.1f}" for r in rows])
    line("wall time, all flights (s)", [f"{r['wall_s']:.0f}" for r in rows])
    for r in rows:
        print(f"\n  {r['name']}: outcomes {r['statuses']}")
        if r["wrong_kinds"]:
            print(f"    wrong matches by what was matched: {r['wrong_kinds']}")
        for key in (
            "wrong_seeds",
            "mirror_seeds",
            "none_seeds",
            "crash_seeds",
            "no_model_seeds",
            "below_margin_seeds",
            "tunnel_lost_seeds",
        ):
            if r[key]:
                print(
                    f"    {key.replace('_', ' ')}: {r[key][:40]}{' …' if len(r[key]) > 40 else ''}"
                )
    if len(rows) == 2:
        new, base = rows
        print(
            f"\n  new / baseline: correct {new['correct']}/{base['correct']} "
            f"({new['correct'] / max(base['correct'], 1):.2f}x), models "
            f"{new['models']}/{base['models']} ({new['models'] / max(base['models'], 1):.2f}x), "
            f"crashes {new['crashes']} vs {base['crashes']}"
        )
    new = rows[0]
    n = max(new["n"], 1)
    goals = [
        ("correct >= 98 %", new["correct"] / n >= 0.98),
        ("correct >= 98 % of flights that took off", new["correct_flew"] >= 0.98 * new["flew"]),
        ("no mirror match", new["mirror"] == 0),
        ("wrong <= 0.5 %", new["wrong"] / n <= 0.005),
        ("model in >= 95 % of matches", new["models"] >= 0.95 * max(new["correct"], 1)),
        ("median IoU >= 0.85", new["iou_median"] >= 0.85),
        ("tunnels kept >= 90 %", new["tunnels"][0] >= 0.9 * new["tunnels"][1]),
        ("no crash", new["crashes"] == 0),
        ("every crash reported as one", new["crashes_hidden"] == 0),
        ("no pass under 2 m", new["below_2m"] == 0),
        ("clearance >= margin", new["below_margin"] == 0),
    ]
    print(
        "\n  goals ("
        + new["name"]
        + "): "
        + ", ".join(f"{g}: {'met' if ok else 'NOT met'}" for g, ok in goals)
    )


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="the smallest run: --scenes 2")
    parser.add_argument("--scenes", type=int, default=200)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument(
        "--baseline",
        default=None,
        help=f"baseline commit [default: {BASELINE}; with --town {TOWN_BASELINE}]",
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--variants", default="new,baseline")
    parser.add_argument("--seeds", default=None, help="comma-separated seeds (instead of a range)")
    parser.add_argument("--keep", type=Path, default=None, help="keep recordings and scenes here")
    parser.add_argument(
        "--random-home",
        action="store_true",
        help="each scene's home anywhere within 60° of the equator, the vehicle facing any way",
    )
    parser.add_argument(
        "--town",
        action="store_true",
        help="town scenes (HardOptions.town()): a breakdown row per class; baseline "
        f"{TOWN_BASELINE} unless --baseline says otherwise",
    )
    parser.add_argument(
        "--world",
        action="store_true",
        help="town scenes with every world knob on: a breakdown row per town and world class; "
        "today's mission only unless --variants says otherwise",
    )
    known = parser.parse_known_args()[0]
    if known.quick:
        parser.set_defaults(scenes=2)
    if known.world:
        parser.set_defaults(variants="new")
    args = parser.parse_args()
    args.town = args.town or args.world
    options = HardOptions.town() if args.town else HardOptions()
    if args.world:
        options = replace(
            options,
            any_light=True,
            any_ground=True,
            ground_areas=True,
            ground_texture=True,
            near_shapes=True,
            anywhere=True,
        )
    if args.random_home:
        options = replace(options, random_home=True)
    if args.baseline is None:
        args.baseline = TOWN_BASELINE if args.town else BASELINE
    variants = args.variants.split(",")
    seeds = (
        [int(x) for x in args.seeds.split(",")]
        if args.seeds
        else list(range(args.first_seed, args.first_seed + args.scenes))
    )
    homes = "; random homes" if args.random_home else ""
    kind = "world" if args.world else "town" if args.town else "hard"
    base = f" (baseline {args.baseline})" if "baseline" in variants else ""
    print(
        f"{len(seeds)} {kind} scenes, seeds {seeds[0]}..{seeds[-1]}{homes}; "
        f"variants {variants}{base}"
    )
    with tempfile.TemporaryDirectory() as tmp_text:
        tmp = args.keep or Path(tmp_text)
        tmp.mkdir(parents=True, exist_ok=True)
        scenes: dict[int, tuple[Scene, HardSceneInfo, Path]] = {}
        for seed in seeds:
            scene, info = generate_hard_scene_with_info(seed=seed, options=options)
            path = tmp / f"hard-{seed}.json"
            path.write_text(json.dumps(scene_to_dict(scene)))
            scenes[seed] = (scene, info, path)
        paths: dict[str, Path | None] = {"new": None}
        if "baseline" in variants:
            paths["baseline"] = extract(args.baseline, tmp / "baseline")
        jobs = []
        for variant in variants:
            pairs = [(str(scenes[s][2]), str(tmp / f"{variant}-{s}.mcap")) for s in seeds]
            k = max(1, len(pairs) // (4 * args.workers))
            jobs += [(variant, pairs[i : i + k]) for i in range(0, len(pairs), k)]
        t0 = time.perf_counter()
        rows: dict[str, list[dict[str, Any]]] = {v: [] for v in variants}
        with ThreadPoolExecutor(args.workers) as pool:
            futures = [(v, pool.submit(fly_batch, pairs, paths[v], tmp)) for v, pairs in jobs]
            for variant, future in futures:
                rows[variant] += future.result()
                done = sum(len(r) for r in rows.values())
                print(
                    f"\r  flown {done}/{len(seeds) * len(variants)} "
                    f"({time.perf_counter() - t0:.0f} s)",
                    end="",
                    flush=True,
                )
        print()
        summaries = []
        for variant in variants:
            results = []
            for row in rows[variant]:
                seed = int(Path(row["record"]).stem.rsplit("-", 1)[1])
                scene, info, _ = scenes[seed]
                results.append(judge(seed, scene, info, row))
            summaries.append(summarise(variant, sorted(results, key=lambda r: r.seed)))
    report(summaries)
    if args.town:
        report_classes(summaries, TOWN_CLASSES + (WORLD_CLASSES if args.world else ()))


if __name__ == "__main__":
    main()
