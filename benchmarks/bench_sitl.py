"""SITL speed: real-time factor at max speed-up, and cost per MAVLink message vs pymavlink.

    python benchmarks/bench_sitl.py [--quick] [--sim-seconds 600] [--messages 20000]

Goal (issue 2): a 10-minute simulated flight in under 10 s wall with telemetry streaming
to one client, on a 2-core machine (a real-time factor of at least 60x). ``--quick``: a
one-minute flight and 2000 messages each way (``--sim-seconds 60 --messages 2000``).
"""

from __future__ import annotations

import argparse
import multiprocessing
import socket
import time

from uavtool.mavlink import mavlink as M
from uavtool.sitl import Mode, Sitl, SitlConfig
from uavtool.sitl.state import MissionItem

SIM_SECONDS = 600.0
GOAL_FACTOR = 60.0  # 10 minutes in 10 s


def _drain(
    port: int, ready: multiprocessing.synchronize.Event, out: multiprocessing.queues.Queue
) -> None:  # type: ignore[name-defined]
    """A ground station in another process: reads and parses everything the vehicle sends."""
    from uavtool.mavlink import FrameParser

    sock = socket.create_connection(("127.0.0.1", port))
    parser = FrameParser()
    ready.set()
    count = 0
    while True:
        data = sock.recv(1 << 16)
        if not data:
            break
        count += len(parser.feed(data))
    out.put(count)


def _patrol(sitl: Sitl) -> None:
    """Arm and fly a square patrol in AUTO for the whole benchmark."""
    home = sitl.config.home
    rel = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    items = [
        MissionItem(
            0,
            M.MAV_FRAME_GLOBAL_INT,
            16,
            0,
            1,
            0,
            0,
            0,
            0,
            home.lat_e7,
            home.lon_e7,
            home.alt_amsl_m,
        ),
        MissionItem(1, rel, 22, 0, 1, 0, 0, 0, 0, 0, 0, 30),
    ]
    corners = [(9000, 0), (9000, 11000), (0, 11000), (0, 0)]  # a ~100 m square
    for lap in range(40):
        for dlat, dlon in corners:
            items.append(
                MissionItem(
                    len(items),
                    rel,
                    16,
                    0,
                    1,
                    0,
                    0,
                    0,
                    0,
                    home.lat_e7 + dlat,
                    home.lon_e7 + dlon,
                    30 + (lap % 3) * 5,
                )
            )
    sitl.autopilot.mission.replace(items)
    sitl.autopilot.set_mode(Mode.GUIDED)
    sitl.autopilot.arm(force=False)
    assert sitl.autopilot.set_mode(Mode.AUTO).ok


def bench_real_time_factor(sim_seconds: float = SIM_SECONDS) -> tuple[float, int]:
    sitl = Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=1e9))
    ready = multiprocessing.Event()
    out: multiprocessing.Queue[int] = multiprocessing.Queue()
    proc = multiprocessing.Process(target=_drain, args=(sitl.ports[0], ready, out))
    proc.start()
    ready.wait(10)
    while not sitl.sessions:
        sitl.poll(0.01)
    _patrol(sitl)
    t0 = time.perf_counter()
    sitl.run(duration_s=sim_seconds)
    wall = time.perf_counter() - t0
    sent = sum(s.link.frames_sent for s in sitl.sessions)
    sitl.close()
    received = out.get(timeout=30)
    proc.join(10)
    assert received == sent, f"client parsed {received} of {sent} frames"
    moved = sitl.autopilot.state.pos_ned_m
    print(f"  flew to N{moved[0]:.0f} E{moved[1]:.0f} m, {sitl.steps} steps, {sent} frames sent")
    return wall, sent


def bench_message_cost(n: int = 20_000) -> tuple[float, float]:
    """µs per telemetry message: our build+pack+send vs pymavlink's own encode+send."""
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.bind(("127.0.0.1", 0))
    sink.setblocking(False)
    addr = sink.getsockname()
    sitl = Sitl(SitlConfig(endpoints=(f"udpout:{addr[0]}:{addr[1]}",), speedup=1e9))
    session = sitl.sessions[0]
    telemetry = sitl.telemetry
    ids = [
        M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
        M.MAVLINK_MSG_ID_ATTITUDE,
        M.MAVLINK_MSG_ID_VFR_HUD,
        M.MAVLINK_MSG_ID_SYS_STATUS,
        M.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    ]

    def drain() -> None:
        try:
            while True:
                sink.recv(4096)
        except BlockingIOError:
            pass

    t0 = time.perf_counter()
    for i in range(n):
        session.send(telemetry.build(ids[i % 5]))
        if i % 200 == 0:
            drain()
    ours = (time.perf_counter() - t0) / n * 1e6

    class _File:
        def __init__(self) -> None:
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

        def write(self, buf: bytes) -> None:
            self.sock.sendto(buf, addr)

    mav = M.MAVLink(_File(), srcSystem=1, srcComponent=1)
    senders = [
        lambda: mav.global_position_int_send(
            1000, -353632610, 1491652300, 594000, 10000, 0, 0, 0, 35300
        ),
        lambda: mav.attitude_send(1000, 0.01, -0.02, 1.2, 0.0, 0.0, 0.0),
        lambda: mav.vfr_hud_send(3.0, 3.0, 353, 45, 594.0, 0.0),
        lambda: mav.sys_status_send(1, 1, 1, 150, 16800, 1200, 99, 0, 0, 0, 0, 0, 0),
        lambda: mav.local_position_ned_send(1000, 1.0, 2.0, -10.0, 0.5, 0.1, 0.0),
    ]
    t0 = time.perf_counter()
    for i in range(n):
        senders[i % 5]()
        if i % 200 == 0:
            drain()
    base = (time.perf_counter() - t0) / n * 1e6
    sitl.close()
    sink.close()
    return ours, base


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick", action="store_true", help="the smallest run: --sim-seconds 60 --messages 2000"
    )
    parser.add_argument(
        "--sim-seconds", type=float, default=SIM_SECONDS, help="flight length (default: 600)"
    )
    parser.add_argument(
        "--messages", type=int, default=20_000, help="messages timed each way (default: 20000)"
    )
    if parser.parse_known_args()[0].quick:
        parser.set_defaults(sim_seconds=60.0, messages=2000)
    args = parser.parse_args()
    sim_s = args.sim_seconds
    print(f"uavtool SITL benchmark ({multiprocessing.cpu_count()} cores)")
    wall, sent = bench_real_time_factor(sim_s)
    goal_s = sim_s / GOAL_FACTOR
    print(
        f"  {sim_s / 60:g}-minute flight at max speed-up: {wall:.2f} s wall, "
        f"real-time factor {sim_s / wall:.0f}x (goal: < {goal_s:g} s, i.e. >= "
        f"{GOAL_FACTOR:.0f}x) -> {'PASS' if wall < goal_s else 'FAIL'}"
    )
    print(f"  telemetry to one TCP client: {sent / wall:,.0f} frames/s wall")
    ours, base = bench_message_cost(args.messages)
    print(
        f"  cost per telemetry message: uavtool build+pack+send {ours:.2f} us, "
        f"pymavlink encode+send {base:.2f} us, ratio {ours / base:.2f}x"
    )


if __name__ == "__main__":
    main()
