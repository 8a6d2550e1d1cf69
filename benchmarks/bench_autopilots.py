"""The same mission (the paper scene, defaults) on every vehicle here: the built-in one,
ArduPilot's ArduCopter SITL (``UAVTOOL_ARDUCOPTER``) and PX4's SITL with SIH (``UAVTOOL_PX4``),
PX4 both with DO_REPOSITION in Hold (uavtool's choice) and with an OFFBOARD setpoint stream.
The real autopilots run ``--speedup`` times faster than real time; the mission is timed by the
vehicle's clock, so its flight time does not depend on it.

    python benchmarks/bench_autopilots.py [--quick] [--speedup 5] [--runs 1]

Prints one row per vehicle (outcome, match, IoU, flight time, route, closest clearance, wall
time) and each flight time as a ratio of the built-in vehicle's. Vehicles whose builds are not
here are listed as skipped. ``--quick`` flies the built-in vehicle only.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from uavtool.autopilot import PX4, Autopilot, for_vehicle  # noqa: E402
from uavtool.runner.fly import FlightSummary, FlyConfig, fly  # noqa: E402

ARDUCOPTER_MOUNT = (
    "MNT1_TYPE 1\nMNT1_PITCH_MIN -90\nMNT1_PITCH_MAX 0\nSERVO9_FUNCTION 7\nSERVO10_FUNCTION 6\n"
)


@dataclass(frozen=True)
class Vehicle:
    name: str
    available: str  # "" when it can fly here, else why not
    start: Callable[[Path], AbstractContextManager[str | None]]  # -> connect URL (None: built-in)
    autopilot_for: Callable[[object], Autopilot] = for_vehicle


@contextmanager
def _builtin(_tmp: Path) -> Iterator[str | None]:
    yield None


def _vehicles() -> list[Vehicle]:
    from tests.integration import peers  # here: it reads UAVTOOL_PEER_SPEEDUP when imported

    @contextmanager
    def arducopter(tmp: Path) -> Iterator[str | None]:
        with peers.arducopter(tmp, params=ARDUCOPTER_MOUNT, home="50.0647,19.945,219,0") as port:
            yield f"tcp:127.0.0.1:{port}"

    @contextmanager
    def px4(tmp: Path) -> Iterator[str | None]:
        with peers.px4(tmp, params=peers.PX4_GIMBAL) as port:
            yield f"udpin:0.0.0.0:{port}"

    ardu = (
        "" if peers.ARDUCOPTER and Path(peers.ARDUCOPTER).is_file() else "UAVTOOL_ARDUCOPTER unset"
    )
    px = "" if peers.PX4 and Path(peers.PX4).exists() else "UAVTOOL_PX4 unset"
    return [
        Vehicle("built-in (lockstep)", "", _builtin),
        Vehicle("ArduCopter SITL", ardu, arducopter),
        Vehicle("PX4 SIH, DO_REPOSITION", px, px4),
        Vehicle("PX4 SIH, OFFBOARD", px, px4, lambda _hb: PX4(movement="offboard")),
    ]


def _fly(vehicle: Vehicle, tmp: Path) -> FlightSummary:
    with vehicle.start(tmp) as connect:
        config = FlyConfig(connect=connect, record=tmp / "f.mcap", connect_timeout_s=120.0)
        return fly(config, autopilot_for=vehicle.autopilot_for)


def _row(name: str, flights: list[FlightSummary], base_s: float | None) -> str:
    s = flights[-1]
    e = s.evaluation
    flight = statistics.median(f.flight_time_s for f in flights)
    wall = statistics.median(f.wall_time_s for f in flights)
    ratio = f"{flight / base_s:5.2f}x" if base_s else "  1.00x"
    iou = f"{e.model_iou:.3f}" if e.model_iou is not None else "-"
    clearance = f"{s.clearance_m:.2f}" if s.clearance_m is not None else "-"
    match = f"{e.matched_building or '-'}" + (
        "" if not e.matched_building else " ok" if e.matched_building == e.target_building
        else " WRONG"
    )  # fmt: skip
    return (
        f"{name:<24} {s.outcome.status.value:<10} {match:<9} {iou:>6} {flight:8.1f} {ratio} "
        f"{s.route_length_m:7.1f} {clearance:>6} {wall:7.1f}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="the built-in vehicle only")
    parser.add_argument("--speedup", type=float, default=5.0, help="the real SITLs' speed-up")
    parser.add_argument("--runs", type=int, default=1, help="flights per vehicle (medians)")
    args = parser.parse_args()
    os.environ["UAVTOOL_PEER_SPEEDUP"] = f"{args.speedup:g}"
    vehicles = _vehicles()[:1] if args.quick else _vehicles()
    print(f"{'vehicle':<24} {'outcome':<10} {'match':<9} {'IoU':>6} {'flight s':>8} {'ratio':>6} "
          f"{'route m':>7} {'clear m':>6} {'wall s':>7}")  # fmt: skip
    base_s: float | None = None
    for vehicle in vehicles:
        if vehicle.available:
            print(f"{vehicle.name:<24} skipped: {vehicle.available}")
            continue
        flights = []
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as tmp:
                flights.append(_fly(vehicle, Path(tmp)))
        print(_row(vehicle.name, flights, base_s), flush=True)
        if base_s is None:
            base_s = statistics.median(f.flight_time_s for f in flights)
    print(f"ratio: flight time (vehicle clock) over the built-in vehicle's; real SITLs at "
          f"{args.speedup:g}x real time")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
