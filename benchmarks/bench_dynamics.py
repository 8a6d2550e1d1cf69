"""The built-in vehicle's dynamics beside ArduCopter's own SITL: one command sequence sent to
both over MAVLink, and the whole ``uavtool fly`` mission in wind, printed side by side and as
ratios (built-in over ArduCopter).

    python benchmarks/bench_dynamics.py [--quick] [--speedup 10] [--winds 0,5,10]
                                        [--no-mission] [--traces DIR]

The manoeuvres, in GUIDED, timed by the vehicle's own clock (LOCAL_POSITION_NED's and
ATTITUDE's time_boot_ms):

1. NAV_TAKEOFF to 45 m: seconds until the vehicle is within 1 m of 45 m;
2. a 50 m reposition north: seconds until within 1 m, and the overshoot past the target;
3. a 40 m climb (45 -> 85 m): seconds until within 1 m;
4. a 90° turn (CONDITION_YAW): seconds until within 2° of the new heading;
5. a 30 s hold in SIM_WIND_SPD 8 from 270°, SIM_WIND_TURB 2, after 20 s to settle: the
   horizontal RMS distance from the hold point, and the roll and pitch RMS;
6. RTL from there in calm air: seconds until landed (disarmed);

then ``uavtool fly`` on the paper scene at each wind (from 270°, turbulence 2): flight time,
route, and the battery used between arming and landing (mAh and Wh, from BATTERY_STATUS).

ArduCopter is ``UAVTOOL_ARDUCOPTER`` (``.ci/run`` points it at ``../shared/peers``); without it
the peer's column is skipped and the reason printed. ``--quick`` flies the built-in vehicle only
and the mission calm. The goals (issue 44): every manoeuvre within ±15 % of ArduCopter's
(the hold's error and attitude RMS within ×1.5), the mission's time and route within ±10 % at
each wind, its battery within ±20 %.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from uavtool.mavlink.dialect import mavlink as M  # noqa: E402

HOME = "-35.363261,149.165230,584,353"  # ArduPilot SITL's default home (CMAC)
ARDUCOPTER_MOUNT = (
    "MNT1_TYPE 1\nMNT1_PITCH_MIN -90\nMNT1_PITCH_MAX 0\nSERVO9_FUNCTION 7\nSERVO10_FUNCTION 6\n"
)
GUIDED = 4
RTL = 6
POS_ONLY = 0b0000_1111_1111_1000  # SET_POSITION_TARGET_LOCAL_NED: position only
POS_YAW = 0b0000_1001_1111_1000  # position and yaw
HOLD_WIND = (8.0, 270.0, 2.0)  # SIM_WIND_SPD, SIM_WIND_DIR, SIM_WIND_TURB


@dataclass
class Probe:
    """A ground station's view of one vehicle: the latest position, attitude and battery, and
    every sample since the last ``mark``, on the vehicle's clock (seconds since its boot)."""

    conn: Any
    t_s: float = 0.0
    ned: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    armed: bool = False
    mode: int = -1
    consumed_mah: float = 0.0
    energy_j: float = 0.0
    positions: list[tuple[float, float, float, float]] = field(default_factory=list)
    attitudes: list[tuple[float, float, float, float]] = field(default_factory=list)
    texts: list[str] = field(default_factory=list)
    trace: list[tuple[float, ...]] = field(default_factory=list)  # (t, n, e, d, r, p, y) all
    events: list[tuple[float, str]] = field(default_factory=list)
    _beat_at: float = 0.0

    def send_heartbeat(self) -> None:
        now = time.monotonic()
        if now - self._beat_at > 0.5:
            self._beat_at = now
            self.conn.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)

    def pump(self, until: Callable[[Probe], bool], timeout_s: float) -> bool:
        """Read messages until ``until(self)`` holds (True) or ``timeout_s`` of vehicle time
        pass (False)."""
        start = self.t_s
        wall_deadline = time.monotonic() + timeout_s + 120.0
        while True:
            self.send_heartbeat()
            msg = self.conn.recv_match(blocking=True, timeout=0.05)
            if msg is not None:
                self._take(msg)
                if until(self):
                    return True
            if self.t_s - start > timeout_s or time.monotonic() > wall_deadline:
                return False

    def wait_s(self, seconds: float) -> None:
        end = self.t_s + seconds
        self.pump(lambda p: p.t_s >= end, seconds + 1.0)

    def _take(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "LOCAL_POSITION_NED":
            self.t_s = max(self.t_s, msg.time_boot_ms / 1000.0)
            self.ned = (msg.x, msg.y, msg.z)
            self.positions.append((self.t_s, msg.x, msg.y, msg.z))
            self.trace.append((self.t_s, msg.x, msg.y, msg.z, *self.rpy_deg))
        elif kind == "ATTITUDE":
            self.t_s = max(self.t_s, msg.time_boot_ms / 1000.0)
            self.rpy_deg = tuple(math.degrees(v) for v in (msg.roll, msg.pitch, msg.yaw))  # type: ignore[assignment]
            self.attitudes.append((self.t_s, *self.rpy_deg))
        elif kind == "HEARTBEAT" and msg.get_srcComponent() == 1 and msg.type != M.MAV_TYPE_GCS:
            self.armed = bool(msg.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)
            self.mode = msg.custom_mode
        elif kind == "BATTERY_STATUS" and msg.id == 0:
            self.consumed_mah = float(msg.current_consumed)
            self.energy_j = float(msg.energy_consumed) * 100.0
        elif kind == "STATUSTEXT":
            self.texts.append(f"{self.t_s:7.1f} {msg.text}")

    def mark(self) -> None:
        self.positions.clear()
        self.attitudes.clear()

    def event(self, name: str) -> None:
        self.events.append((self.t_s, name))

    def command(self, command: int, *params: float) -> None:
        p = [*params, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0][:7]
        self.conn.mav.command_long_send(1, 1, command, 0, *p)

    def set_param(self, name: str, value: float) -> None:
        self.conn.mav.param_set_send(1, 1, name.encode(), value, M.MAV_PARAM_TYPE_REAL32)
        self.wait_s(0.5)

    def go_to(self, n: float, e: float, d: float, yaw_deg: float | None = None) -> None:
        mask, yaw = (POS_ONLY, 0.0) if yaw_deg is None else (POS_YAW, math.radians(yaw_deg))
        self.conn.mav.set_position_target_local_ned_send(
            0, 1, 1, M.MAV_FRAME_LOCAL_NED, mask, n, e, d, 0, 0, 0, 0, 0, 0, yaw, 0
        )


def _request_streams(p: Probe) -> None:
    for msg_id, hz in (
        (M.MAVLINK_MSG_ID_LOCAL_POSITION_NED, 25.0),
        (M.MAVLINK_MSG_ID_ATTITUDE, 25.0),
        (M.MAVLINK_MSG_ID_BATTERY_STATUS, 2.0),
    ):
        p.command(M.MAV_CMD_SET_MESSAGE_INTERVAL, msg_id, 1e6 / hz)
        p.wait_s(0.2)


def _arm(p: Probe) -> None:
    for _ in range(120):
        p.conn.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, GUIDED)
        p.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        if p.pump(lambda q: q.armed and q.mode == GUIDED, 2.0):
            return
    raise RuntimeError("the vehicle never armed: " + " | ".join(p.texts[-5:]))


def _first(samples: list[tuple[float, ...]], ok: Callable[[tuple[float, ...]], bool]) -> float:
    for s in samples:
        if ok(s):
            return s[0]
    return math.nan


def _rms(values: list[float]) -> float:
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else math.nan


def manoeuvres(p: Probe) -> dict[str, float]:
    """Fly the sequence; one figure per name."""
    out: dict[str, float] = {}
    _request_streams(p)
    for name, value in (("SIM_WIND_SPD", 0.0), ("SIM_WIND_TURB", 0.0), ("SIM_WIND_DIR", 270.0)):
        p.set_param(name, value)
    _arm(p)
    n0, e0, _ = p.ned
    # 1. take-off to 45 m
    p.mark()
    t0 = p.t_s
    p.event("take-off")
    p.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, 45.0)
    p.pump(lambda q: abs(-q.ned[2] - 45.0) <= 1.0, 90.0)
    out["take-off to 45 m, s"] = p.t_s - t0
    p.wait_s(8.0)
    # 2. 50 m north
    n1, e1, _ = p.ned
    target_n = n1 + 50.0
    p.mark()
    t0 = p.t_s
    p.event("reposition")
    p.go_to(target_n, e1, -45.0)
    p.pump(lambda q: math.hypot(q.ned[0] - target_n, q.ned[1] - e1) <= 1.0, 60.0)
    out["50 m reposition, s"] = p.t_s - t0
    p.wait_s(10.0)
    out["reposition overshoot, m"] = max(0.0, max(s[1] for s in p.positions) - target_n)
    # 3. climb 45 -> 85 m
    p.mark()
    t0 = p.t_s
    p.event("climb")
    p.go_to(target_n, e1, -85.0)
    p.pump(lambda q: abs(-q.ned[2] - 85.0) <= 1.0, 90.0)
    out["40 m climb, s"] = p.t_s - t0
    p.wait_s(5.0)
    # 4. 90° turn
    start_yaw = p.rpy_deg[2] % 360.0
    goal = (start_yaw + 90.0) % 360.0
    p.mark()
    t0 = p.t_s
    p.event("turn")
    p.command(M.MAV_CMD_CONDITION_YAW, goal, 0, 1, 0)
    p.pump(lambda q: abs((q.rpy_deg[2] - goal + 180.0) % 360.0 - 180.0) <= 2.0, 30.0)
    out["90° turn, s"] = p.t_s - t0
    p.wait_s(3.0)
    # 5. hold in wind
    hold_n, hold_e, _ = p.ned
    p.go_to(hold_n, hold_e, -85.0, goal)  # nose east: the wind from the west at its tail
    speed, from_deg, turb = HOLD_WIND
    p.event("wind")
    p.set_param("SIM_WIND_DIR", from_deg)
    p.set_param("SIM_WIND_SPD", speed)
    p.set_param("SIM_WIND_TURB", turb)
    p.wait_s(20.0)
    p.mark()
    p.event("hold")
    p.wait_s(30.0)
    err = [math.hypot(n - hold_n, e - hold_e) for _, n, e, _ in p.positions]
    out["hold: horizontal RMS error, m"] = _rms(err)
    out["hold: roll RMS, °"] = _rms([a[1] for a in p.attitudes])
    out["hold: pitch RMS, °"] = _rms([a[2] for a in p.attitudes])
    # 6. RTL in calm air
    p.set_param("SIM_WIND_SPD", 0.0)
    p.set_param("SIM_WIND_TURB", 0.0)
    p.wait_s(15.0)
    p.mark()
    t0 = p.t_s
    p.event("rtl")
    p.conn.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, RTL)
    p.pump(lambda q: not q.armed, 240.0)
    out["RTL and landing, s"] = p.t_s - t0
    out["landing: distance from home, m"] = math.hypot(p.ned[0] - n0, p.ned[1] - e0)
    return out


# ---------------------------------------------------------------------- vehicles
@contextmanager
def builtin(speedup: float, tmp: Path) -> Iterator[str]:
    """The built-in vehicle on a TCP port, wall-paced at ``speedup``, as ``uavtool sitl``."""
    del tmp
    from uavtool.sitl import Sitl, SitlConfig
    from uavtool.sitl.config import ARMING_SETTLE_S, parse_home

    home, heading = parse_home(HOME)
    config = SitlConfig(
        endpoints=("tcpin:127.0.0.1:0",),
        home=home,
        home_heading_deg=heading,
        speedup=speedup,
        arming_settle_s=ARMING_SETTLE_S,
        params=(("MNT1_TYPE", 1.0),),
    )
    with Sitl(config) as sitl:
        yield f"tcp:127.0.0.1:{sitl.ports[0]}"


@contextmanager
def arducopter(speedup: float, tmp: Path) -> Iterator[str]:
    os.environ["UAVTOOL_PEER_SPEEDUP"] = f"{speedup:g}"
    from tests.integration import peers

    peers.SPEEDUP = speedup
    with peers.arducopter(tmp, params=ARDUCOPTER_MOUNT, home=HOME) as port:
        yield f"tcp:127.0.0.1:{port}"


def _arducopter_missing() -> str:
    path = os.environ.get("UAVTOOL_ARDUCOPTER", "")
    if not path:
        return "UAVTOOL_ARDUCOPTER is unset (point it at ../shared/peers/arducopter/arducopter)"
    if not Path(path).is_file():
        return f"UAVTOOL_ARDUCOPTER={path}: no such file"
    return ""


def fly_manoeuvres(start: Callable[..., Any], speedup: float, traces: Path | None, name: str):
    from pymavlink import mavutil

    with tempfile.TemporaryDirectory() as tmp, start(speedup, Path(tmp)) as url:
        conn = None
        for _ in range(100):
            try:
                conn = mavutil.mavlink_connection(url, source_system=255, source_component=190)
                break
            except OSError:
                time.sleep(0.2)
        assert conn is not None
        conn.wait_heartbeat(timeout=60)
        probe = Probe(conn)
        try:
            figures = manoeuvres(probe)
        finally:
            conn.close()
        if traces is not None:
            traces.mkdir(parents=True, exist_ok=True)
            (traces / f"{name}.json").write_text(
                json.dumps(
                    {
                        "figures": figures,
                        "trace": probe.trace,
                        "events": probe.events,
                        "texts": probe.texts,
                    }
                )
            )
        return figures


# ---------------------------------------------------------------------- the mission
@dataclass(frozen=True)
class MissionFigures:
    status: str
    flight_s: float
    route_m: float
    mah: float
    wh: float


def _battery_used(recording: Path) -> tuple[float, float]:
    """mAh and Wh drawn from arming to disarming: SYS_STATUS's current and voltage, integrated
    on the vehicle's clock (time_boot_ms). Both vehicles send it; ArduCopter does not stream
    BATTERY_STATUS to this link."""
    from pymavlink import mavutil

    from uavtool.recording.tlog import export_tlog

    tlog = recording.with_suffix(".tlog")
    export_tlog(recording, tlog)
    log = mavutil.mavlink_connection(str(tlog), dialect="ardupilotmega")
    armed = False
    now_s = last_s = 0.0
    mah = wh = 0.0
    seen = False
    while (msg := log.recv_match()) is not None:
        kind = msg.get_type()
        if hasattr(msg, "time_boot_ms"):
            now_s = max(now_s, msg.time_boot_ms / 1000.0)
        elif kind == "HEARTBEAT" and msg.get_srcComponent() == 1 and msg.type != M.MAV_TYPE_GCS:
            armed = bool(msg.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED)
        elif kind == "SYS_STATUS":
            if armed and last_s and msg.current_battery >= 0:
                amps, volts = msg.current_battery / 100.0, msg.voltage_battery / 1000.0
                dt = now_s - last_s
                mah += amps * dt / 3.6
                wh += amps * volts * dt / 3600.0
                seen = True
            last_s = now_s
    return (mah, wh) if seen else (math.nan, math.nan)


def fly_mission(connect: str | None, wind_ms: float, tmp: Path) -> MissionFigures:
    out = tmp / f"mission-{wind_ms:g}.mcap"
    args = [sys.executable, "-m", "uavtool", "fly", "--output", str(out), "--timeout", "120"]
    if connect is None:
        args += ["--wind", f"{wind_ms:g},270", "--param", "SIM_WIND_TURB=2"]
    else:
        args += ["--connect", connect, "--param", f"SIM_WIND_SPD={wind_ms:g}",
                 "--param", "SIM_WIND_DIR=270", "--param", "SIM_WIND_TURB=2"]  # fmt: skip
    run = subprocess.run(args, capture_output=True, text=True, check=False)
    summary = {}
    for line in run.stdout.splitlines():
        key, _, rest = line.partition(" ")
        summary[key] = rest.strip()
    status = summary.get("outcome", f"exit {run.returncode}").split(":")[0]
    flight = summary.get("flight", "")
    try:
        flight_s = float(flight.split(" s sim")[0])
        route_m = float(flight.split("route ")[1].split(" m")[0])
    except (IndexError, ValueError):
        flight_s = route_m = math.nan
    mah, wh = _battery_used(out) if out.exists() else (math.nan, math.nan)
    return MissionFigures(status, flight_s, route_m, mah, wh)


# ---------------------------------------------------------------------- the table
def _ratio(ours: float, theirs: float | None) -> str:
    if theirs is None or not math.isfinite(ours) or not theirs:
        return "     -"
    return f"{ours / theirs:6.2f}"


def _judge(ours: float, theirs: float | None, low: float, high: float) -> str:
    if theirs is None or not theirs or not math.isfinite(ours):
        return ""
    return "ok" if low <= ours / theirs <= high else "MISSED"


def print_manoeuvres(ours: dict[str, float], theirs: dict[str, float] | None) -> None:
    print(f"\n{'manoeuvre':<34} {'built-in':>9} {'ArduCopter':>10} {'ratio':>6}  goal")
    for name, value in ours.items():
        other = None if theirs is None else theirs[name]
        shown = "-" if other is None else f"{other:10.2f}"
        if name.startswith("landing:"):
            goal, verdict = "-", ""
        elif name.startswith("hold:"):
            goal, verdict = "x1.5", _judge(value, other, 1 / 1.5, 1.5)
        else:
            goal, verdict = "±15 %", _judge(value, other, 0.85, 1.15)
        print(f"{name:<34} {value:9.2f} {shown:>10} {_ratio(value, other)}  {goal} {verdict}")


def print_mission(
    wind: float, ours: MissionFigures, theirs: MissionFigures | None, *, first: bool
) -> None:
    if first:
        print(f"\n{'mission: paper, wind from 270°, TURB 2':<40} {'built-in':>10} "
              f"{'ArduCopter':>10} {'ratio':>6}  goal")  # fmt: skip
    t = theirs
    rows = (
        ("outcome", ours.status, None if t is None else t.status, "", 0.0),
        ("flight time, s", ours.flight_s, None if t is None else t.flight_s, "±10 %", 0.1),
        ("route, m", ours.route_m, None if t is None else t.route_m, "±10 %", 0.1),
        ("battery, mAh", ours.mah, None if t is None else t.mah, "±20 %", 0.2),
        ("battery, Wh", ours.wh, None if t is None else t.wh, "±20 %", 0.2),
    )
    for name, mine, other, goal, tol in rows:
        label = f"wind {wind:g} m/s: {name}"
        if isinstance(mine, str):
            print(f"{label:<40} {mine:>10} {other or '-':>10}")
            continue
        assert not isinstance(other, str)
        verdict = _judge(mine, other, 1.0 - tol, 1.0 + tol)
        shown = "-" if other is None else f"{other:10.1f}"
        print(f"{label:<40} {mine:10.1f} {shown:>10} {_ratio(mine, other)}  {goal} {verdict}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="built-in only, calm mission")
    parser.add_argument("--speedup", type=float, default=10.0, help="both vehicles' speed-up")
    parser.add_argument("--winds", default="0,5,10", help="the mission's winds, m/s")
    parser.add_argument("--no-mission", action="store_true", help="the manoeuvres only")
    parser.add_argument("--no-manoeuvres", action="store_true", help="the mission only")
    parser.add_argument("--traces", type=Path, default=None, help="write each trace as JSON")
    parser.add_argument("--only", choices=("builtin", "arducopter"), help="one vehicle only")
    args = parser.parse_args()
    missing = "--quick" if args.quick else _arducopter_missing()
    if args.only == "builtin":
        missing = "--only builtin"
    if missing:
        print(f"ArduCopter: skipped ({missing})")
    speedup = 50.0 if args.quick else args.speedup  # the built-in vehicle keeps up with any
    if not args.no_manoeuvres:
        ours = theirs = None
        if args.only != "arducopter":
            ours = fly_manoeuvres(builtin, speedup, args.traces, "builtin")
        if not missing:
            theirs = fly_manoeuvres(arducopter, args.speedup, args.traces, "arducopter")
        if ours is None:
            print(theirs)
        else:
            print_manoeuvres(ours, theirs)
    if not args.no_mission and args.only != "arducopter":
        winds = [0.0] if args.quick else [float(w) for w in args.winds.split(",")]
        for i, wind in enumerate(winds):
            with tempfile.TemporaryDirectory() as tmp:
                ours_m = fly_mission(None, wind, Path(tmp))
                theirs_m = None
                if not missing:
                    with arducopter(args.speedup, Path(tmp)) as url:
                        theirs_m = fly_mission(url, wind, Path(tmp))
            print_mission(wind, ours_m, theirs_m, first=i == 0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
