"""A fleet against one vehicle on wide hard scenes (issue 46's measure), in one run, as ratios.

Every scene is a generated hard scene spread over ±75 m (buildings 6–9, the sweep's hard
options), searched over a square of 80 m (``mission.search_radius_m=80``). Each is flown twice
in lockstep on the built-in vehicles, same seed: by one vehicle with the search mission
(``search``), and by ``--vehicles N`` (default 3) with ``fleet-search``. Per scene it prints
both outcomes, whether the matched building is the scene's target, the vehicle time until the
model was built and until the last vehicle landed, the fleet's closest approach; then:

- the fleet's time to the model over one vehicle's (median and mean of the scenes where both
  built it; the issue's goal: <= 0.45), and the same for the whole flight (to the last
  landing);
- right / wrong matches, crashes and the models' IoU of each, and separation breaches of the
  fleet (goal: the same or better right rate, 0 wrong, 0 crashes, 0 breaches);
- lockstep wall time per vehicle-second of each, and their ratio (goal: <= 1.2: a fleet of
  N costs N vehicles' simulation and rendering, so per vehicle-second of *each* vehicle).

    python benchmarks/bench_fleet.py [--first 61001] [--count 100] [--vehicles 3] [--quick]

``--quick``: two scenes.
"""

from __future__ import annotations

import argparse
import statistics
import time

from uavtool.mission import Params, Status
from uavtool.mission.fleet_search import FleetSearchParams
from uavtool.mission.params import with_overrides
from uavtool.runner.fleet import fly_fleet
from uavtool.runner.fly import FlyConfig, fly
from uavtool.world.hard import HardOptions, generate_hard_scene

SPREAD_M = 75.0
RADIUS_M = 80.0
GOAL_TIME_RATIO = 0.45
GOAL_WALL_RATIO = 1.2


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--first", type=int, default=61001)
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--vehicles", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="two scenes")
    args = ap.parse_args()
    if args.quick:
        args.count = 2
    options = HardOptions(spread_m=SPREAD_M, min_buildings=6, max_buildings=9)
    one_params = with_overrides(Params(), {"mission.search_radius_m": RADIUS_M})
    fleet_params = with_overrides(FleetSearchParams(), {"mission.search_radius_m": RADIUS_M})
    rows = []
    print(
        f"{'seed':>6}  {'one: status':<15} {'right':>5} {'model s':>8} {'all s':>6}  "
        f"{'fleet: status':<15} {'right':>5} {'model s':>8} {'all s':>6} {'closest':>7}"
    )
    for seed in range(args.first, args.first + args.count):
        scene = generate_hard_scene(seed=seed, options=options)
        one_model: list[float] = []
        wall0 = time.perf_counter()
        one = fly(
            FlyConfig(scene=scene, params=one_params, no_record=True, seed=seed),
            progress=lambda text, t, out=one_model: _model_time(text, t, out),
        )
        one_wall = time.perf_counter() - wall0
        fleet_model: list[float] = []
        wall0 = time.perf_counter()
        fleet = fly_fleet(
            FlyConfig(
                scene=scene,
                params=fleet_params,
                no_record=True,
                seed=seed,
                mission="fleet-search",
                vehicles=args.vehicles,
                offset_line=None,  # the first line clear of the buildings around home
            ),
            progress=lambda _v, text, t, out=fleet_model: _model_time(text, t, out),
        )
        fleet_wall = time.perf_counter() - wall0
        e1, ef = one.evaluation, fleet.evaluation
        row = {
            "seed": seed,
            "one": one.outcome.status,
            "one_right": _right(e1.matched_building, e1.target_building),
            "one_model_s": one_model[0] if one_model else None,
            "one_s": one.vehicle_time_s,
            "one_wall_per_s": one_wall / max(one.vehicle_time_s, 1e-9),
            "fleet": fleet.status,
            "fleet_right": _right(ef.matched_building, ef.target_building) if ef else None,
            "fleet_model_s": fleet_model[0] if fleet_model else None,
            "fleet_s": fleet.vehicle_time_s,
            "fleet_wall_per_s": fleet_wall / max(fleet.vehicle_time_s * args.vehicles, 1e-9),
            "one_iou": e1.model_iou,
            "fleet_iou": ef.model_iou if ef else None,
            "closest_m": fleet.closest_approach_m,
            "separation_m": fleet.separation_m,
        }
        rows.append(row)
        print(
            f"{seed:>6}  {row['one'].value:<15} {_word(row['one_right']):>5} "
            f"{_secs(row['one_model_s']):>8} {row['one_s']:>6.0f}  {row['fleet'].value:<15} "
            f"{_word(row['fleet_right']):>5} {_secs(row['fleet_model_s']):>8} "
            f"{row['fleet_s']:>6.0f} {row['closest_m']:>7.2f}",
            flush=True,
        )
    _report(rows, args.vehicles)


def _model_time(text: str, t: object, out: list[float]) -> None:
    if text.startswith("model built:") and t is not None and not out:
        out.append(t.time_boot_ms / 1000.0)  # type: ignore[attr-defined]


def _right(matched: str, target: str) -> bool | None:
    return None if not matched else matched == target


def _word(right: bool | None) -> str:
    return "-" if right is None else ("yes" if right else "WRONG")


def _secs(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f}"


def _report(rows: list[dict[str, object]], vehicles: int) -> None:
    both = [r for r in rows if r["one_model_s"] is not None and r["fleet_model_s"] is not None]
    model_ratios = [r["fleet_model_s"] / r["one_model_s"] for r in both]  # type: ignore[operator]
    all_ratios = [r["fleet_s"] / r["one_s"] for r in rows]  # type: ignore[operator]
    n = len(rows)

    def count(key: str, value: object) -> int:
        return sum(1 for r in rows if r[key] == value)

    print()
    print(f"{n} scenes, {vehicles} vehicles against one")
    if model_ratios:
        med = statistics.median(model_ratios)
        print(
            f"time to the model, fleet / one: median {med:.2f}, mean "
            f"{statistics.fmean(model_ratios):.2f} over {len(both)} scenes where both built it "
            f"(goal <= {GOAL_TIME_RATIO}: {'met' if med <= GOAL_TIME_RATIO else 'NOT met'})"
        )
    print(
        f"whole flight (to the last landing), fleet / one: median "
        f"{statistics.median(all_ratios):.2f}, mean {statistics.fmean(all_ratios):.2f}"
    )
    right = f"one {count('one_right', True)}/{n}, fleet {count('fleet_right', True)}/{n}"
    wrong = f"one {count('one_right', False)}, fleet {count('fleet_right', False)}"
    print(f"right matches: {right}; wrong: {wrong}")
    print(
        f"models built: one {sum(1 for r in rows if r['one_model_s'] is not None)}, fleet "
        f"{sum(1 for r in rows if r['fleet_model_s'] is not None)}; crashed: one "
        f"{count('one', Status.CRASHED)}, fleet {count('fleet', Status.CRASHED)}"
    )
    ious = [
        (r["one_iou"], r["fleet_iou"]) for r in rows if None not in (r["one_iou"], r["fleet_iou"])
    ]
    if ious:
        one_iou = statistics.median(a for a, _ in ious)  # type: ignore[type-var]
        fleet_iou = statistics.median(b for _, b in ious)  # type: ignore[type-var]
        print(
            f"model IoU with the true building, median over {len(ious)} scenes where both "
            f"built it: one {one_iou:.3f}, fleet {fleet_iou:.3f}"
        )
    breaches = sum(1 for r in rows if r["closest_m"] < r["separation_m"])  # type: ignore[operator]
    closest = min(r["closest_m"] for r in rows)  # type: ignore[type-var]
    print(f"separation breaches: {breaches} (closest approach of all: {closest:.2f} m)")
    one_wall = statistics.median(r["one_wall_per_s"] for r in rows)  # type: ignore[misc]
    fleet_wall = statistics.median(r["fleet_wall_per_s"] for r in rows)  # type: ignore[misc]
    ratio = fleet_wall / one_wall
    print(
        f"lockstep wall per vehicle-second: one {one_wall * 1000:.2f} ms, fleet "
        f"{fleet_wall * 1000:.2f} ms per vehicle; ratio {ratio:.2f} (goal <= {GOAL_WALL_RATIO}: "
        f"{'met' if ratio <= GOAL_WALL_RATIO else 'NOT met'})"
    )


if __name__ == "__main__":
    main()
