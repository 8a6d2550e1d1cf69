"""Does the mission find the right building when the flight is not perfect?

Flies the built-in SITL as one ``uavtool sweep`` (:func:`uavtool.sweep.run_sweep`: each flight
a Dask task on a local cluster, one recording and one table row per flight) over the
``paper``, ``blocked-front`` and ``dense`` scenes and prints per flight, from the table: did it
match the target building (the runner knows the scene's ground truth), the target's
score(s) at its point of interest (``a→b`` when the mission looked twice), the model's IoU
against the true building, and the flight time (vehicle seconds). Conditions, per scene:

- sensor noise (``--noise``), calm, one flight per seed;
- 6 m/s wind from each direction, noise on;
- the first two wind directions again without noise (the position error alone);
- noise with the vehicle's home heading turned (the photos see the roofs rotated, so their
  perspective steps fall differently).

Each condition is flown with two mission parameter sets in one run: ``new`` (today's
defaults) and ``baseline`` (the same with the robustness features switched off through
their ``mission.*`` keys: roofs joined only when their colours are equal, one look per point
of interest), so the summary compares them on the same seeds. The conditions are the sweep
spec's ``[[cases]]`` (condition × variant), crossed with its scenes; the flights are the same as
when this script flew them one after another, so are the figures. A flight takes ~3–6 s of
one core; the default run (30 conditions × 2) about 3 minutes on two busy cores.

    python benchmarks/bench_mission_robustness.py [--quick]
        [--scenes paper,blocked-front,dense] [--seeds 1,2] [--wind 6]
        [--wind-dirs 0,90,180,270] [--headings 30,60] [--variants new,baseline]
        [--workers 2 | --scheduler ADDRESS] [--out FOLDER]

``--quick``: one condition of each kind, both variants (``--scenes paper --seeds 1
--wind-dirs 0 --headings 30``: 4 conditions, 8 flights).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uavtool.cli.fly import EXIT_CODES
from uavtool.mission.params import valid_keys
from uavtool.sweep import run_sweep
from uavtool.sweep.spec import parse_spec

# The switches that turn today's robustness features off (see MissionParams); keys this
# checkout does not know are left out, so the script also measures older missions.
BASELINE = {"mission.roof_colour_tolerance_dn": 0, "mission.max_looks": 1}


@dataclass(frozen=True, slots=True)
class Condition:
    scene: str
    seed: int
    wind: tuple[float, float] = (0.0, 0.0)
    noise: bool = True
    heading_deg: float = 0.0
    """The vehicle's heading at home (it keeps it over the points of interest); 0: the
    scene's own."""

    @property
    def label(self) -> str:
        wind = f"wind {self.wind[0]:g}@{self.wind[1]:03.0f}" if self.wind[0] else "calm"
        return (
            f"{self.scene:<13s} seed {self.seed:<2d} {'noise' if self.noise else 'clean'} "
            f"{wind:<12s} hdg {self.heading_deg:3.0f}"
        )

    def inputs(self) -> dict[str, Any]:
        """The condition as sweep inputs (the scene is the spec's)."""
        out: dict[str, Any] = {"seed": self.seed, "noise": self.noise}
        if self.wind[0]:
            out |= {"wind_speed_ms": self.wind[0], "wind_from_deg": self.wind[1]}
        if self.heading_deg:
            out["home_heading_deg"] = self.heading_deg
        return out


def conditions(
    scenes: list[str],
    seeds: list[int],
    wind_m_s: float,
    dirs: list[float],
    headings: list[float],
) -> list[Condition]:
    out: list[Condition] = []
    for scene in scenes:
        out.extend(Condition(scene, seed) for seed in seeds)
        windy = [
            Condition(scene, seeds[i % len(seeds)] + 10, (wind_m_s, d)) for i, d in enumerate(dirs)
        ]
        out.extend(windy)
        out.extend(Condition(c.scene, c.seed, c.wind, noise=False) for c in windy[:2])
        out.extend(
            Condition(scene, seeds[i % len(seeds)] + 20, heading_deg=h)
            for i, h in enumerate(headings)
        )
    return out


def sweep_data(
    scenes: list[str], per_scene: list[Condition], variants: dict[str, dict[str, Any]]
) -> dict[str, Any]:
    """The sweep spec: the scenes, crossed with one case per condition and variant (the
    conditions of one scene: they are the same for every scene but for its name)."""
    cases = [
        c.inputs() | {f"set.{k}": v for k, v in settings.items()}
        for c in per_scene
        for settings in variants.values()
    ]
    return {"scenes": {"builtin": scenes}, "cases": cases, "sweep": {"retries": 0}}


def target_scores(r: dict[str, Any]) -> str:
    """The scores at the target building's point(s) of interest, in the order judged."""
    scores = json.loads(r["target_scores"] or "[]")
    return "→".join(f"{v:.3f}" for v in scores) if scores else "not seen"


def row(cond: Condition, variant: str, r: dict[str, Any]) -> str:
    if r["status"] == "error":
        return f"{cond.label} {variant:<8s} ERROR {r['error']}"
    if r["correct"]:
        verdict = "ok"
    elif r["matched_building"]:
        verdict = f"WRONG ({r['matched_building']})"
    else:
        verdict = f"MISSED ({r['status']})"
    iou = f"{r['iou']:.3f}" if r["iou"] is not None else "-"
    return (
        f"{cond.label} {variant:<8s} {verdict:<18s} target {target_scores(r):<14s} "
        f"IoU {iou:<5s} flight {r['flight_time_s']:6.1f} s  wall {r['wall_s']:4.1f} s"
    )


def floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="the smallest run: --scenes paper --seeds 1 --wind-dirs 0 --headings 30",
    )
    parser.add_argument("--scenes", default="paper,blocked-front,dense")
    parser.add_argument("--seeds", default="1,2")
    parser.add_argument("--wind", type=float, default=6.0, help="wind speed, m/s")
    parser.add_argument("--wind-dirs", default="0,90,180,270", help="from, degrees")
    parser.add_argument("--headings", default="30,60", help="home headings, degrees")
    parser.add_argument("--variants", default="new,baseline")
    parser.add_argument("--workers", type=int, default=None, help="default: one per core")
    parser.add_argument("--scheduler", default=None, help="a running Dask scheduler")
    parser.add_argument("--out", type=Path, default=None, help="keep the sweep folder here")
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(scenes="paper", seeds="1", wind_dirs="0", headings="30")
    args = parser.parse_args()
    known = valid_keys()
    baseline = {k: v for k, v in BASELINE.items() if k in known}
    all_variants = {"new": {}, "baseline": baseline}
    variants = {v: all_variants[v] for v in args.variants.split(",")}
    scenes = args.scenes.split(",")
    seeds = [int(s) for s in args.seeds.split(",")]
    dirs, headings = floats(args.wind_dirs), floats(args.headings)
    conds = conditions(scenes, seeds, args.wind, dirs, headings)
    print(f"baseline = today's defaults with {baseline or '(no switch known: same mission)'}")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or Path(tmp) / "sweep"
        per_scene = conditions(scenes[:1], seeds, args.wind, dirs, headings)
        data = sweep_data(scenes, per_scene, variants)
        spec = parse_spec(data, source="bench_mission_robustness", base=Path(tmp), default_out=out)
        result = run_sweep(
            spec,
            exit_codes=EXIT_CODES,
            scheduler=args.scheduler,
            workers=args.workers,
            plots=False,
        )
    flights = [(c, v) for c in conds for v in variants]
    assert len(result.rows) == len(flights), "the sweep was interrupted"
    tally: dict[str, list[dict[str, Any]]] = {v: [] for v in variants}
    for (cond, variant), r in zip(flights, result.rows, strict=True):
        tally[variant].append(r)
        print(row(cond, variant, r))
    kept = f"; table {result.table}" if args.out else ""
    print(f"{len(conds)} conditions, {time.perf_counter() - t0:.0f} s wall{kept}")
    for variant, rows in tally.items():
        ok = sum(bool(r["correct"]) for r in rows)
        wrong = sum(bool(r["matched_building"]) and not r["correct"] for r in rows)
        flight = sum(float(r["flight_time_s"] or 0.0) for r in rows) / max(len(rows), 1)
        print(
            f"{variant:<8s} success {ok}/{len(rows)}, wrong matches {wrong}, "
            f"mean flight {flight:.1f} s"
        )


if __name__ == "__main__":
    main()
