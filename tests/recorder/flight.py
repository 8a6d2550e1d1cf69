"""A flight someone else flies, for the recorder's tests: the built-in vehicle over the paper
scene, flown in AUTO by a scripted ground station (upload, arm, MISSION_START), with a photo
(DO_DIGICAM_CONTROL item) above each building."""

from __future__ import annotations

import socket
import subprocess
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.sitl.client import Client
from uavtool.geo import geo_from_enu
from uavtool.mavlink import mavlink as M
from uavtool.mavlink.dialect import COPTER_MODES
from uavtool.sitl import Sitl, SitlConfig
from uavtool.world import Scene, load_scene

REPO = Path(__file__).resolve().parents[2]
REL = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
# About 30 m over the roofs, as the target picture (`uavtool scene target`) is taken: the red
# building has parts at two heights, and its outline is the target picture's only from about
# that distance (closer, its lower part shows smaller: `uavtool.vision.verify`)
PHOTO_ALT_M = 35.0
# Above each building of the paper scene (ENU metres from home), in visiting order.
STOPS = {"purple": (0.0, 9.0), "yellow": (-13.0, 7.0), "blue": (-11.0, -8.0), "red": (10.0, -8.0)}


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class LinkCounter:
    """The vehicle's frame tap: frames received, per link name."""

    def __init__(self) -> None:
        self.received: Counter[str] = Counter()

    def __call__(self, direction: str, link: Any, raw: bytes) -> None:
        if direction == "in":
            self.received[link.name] += 1


def vehicle(scene: Scene, *, endpoints: tuple[str, ...], tap: LinkCounter | None = None) -> Sitl:
    config = SitlConfig(endpoints=endpoints, speedup=8.0, home=scene.home)
    return Sitl(config, frame_tap=tap)


def mission_items(scene: Scene) -> list[tuple[Any, ...]]:
    home = scene.home
    items: list[tuple[Any, ...]] = [
        (
            M.MAV_CMD_NAV_WAYPOINT,
            M.MAV_FRAME_GLOBAL_INT,
            0,
            0,
            0,
            0,
            home.lat_e7,
            home.lon_e7,
            home.alt_amsl_m,
        ),
        (
            M.MAV_CMD_DO_MOUNT_CONTROL,
            M.MAV_FRAME_MISSION,
            -90,
            0,
            0,
            0,
            0,
            0,
            M.MAV_MOUNT_MODE_MAVLINK_TARGETING,
        ),
        (M.MAV_CMD_NAV_TAKEOFF, REL, 0, 0, 0, 0, 0, 0, PHOTO_ALT_M),
    ]
    for east, north in STOPS.values():
        p = geo_from_enu(home, east, north, 0.0)
        items.append((M.MAV_CMD_NAV_WAYPOINT, REL, 1, 0, 0, 0, p.lat_e7, p.lon_e7, PHOTO_ALT_M))
        items.append((M.MAV_CMD_DO_DIGICAM_CONTROL, M.MAV_FRAME_MISSION, 0, 0, 0, 0, 1, 0, 0))
    items.append((M.MAV_CMD_NAV_LAND, REL, 0, 0, 0, 0, 0, 0, 0))
    return items


def fly_auto_mission(client: Client, scene: Scene) -> None:
    """Upload the mission, arm, start it and wait until the vehicle has landed and disarmed."""
    items = mission_items(scene)
    client.send(M.MAVLink_mission_count_message(1, 1, len(items), 0))
    while True:
        msg = client.wait_for("MISSION_REQUEST_INT", timeout=5)
        cmd, frame, p1, p2, p3, p4, x, y, z = items[msg.seq]
        client.send(
            M.MAVLink_mission_item_int_message(
                1, 1, msg.seq, frame, cmd, 0, 1, p1, p2, p3, p4, x, y, z, 0
            )
        )
        if msg.seq == len(items) - 1:
            break
    assert client.wait_for("MISSION_ACK").type == M.MAV_MISSION_ACCEPTED
    assert client.set_mode("GUIDED").result == M.MAV_RESULT_ACCEPTED
    # Arm after two heartbeats in GUIDED, a second of vehicle time: every link streams its own
    # 1 Hz heartbeat at its own phase, so one GUIDED heartbeat on this link does not mean the
    # recorder's link has had one. At 8x the arm and MISSION_START can otherwise both come
    # between two of its heartbeats, and it rightly logs STABILIZE → AUTO.
    guided = COPTER_MODES["GUIDED"]
    for _ in range(2):
        client.wait_for("HEARTBEAT", lambda m: m.custom_mode == guided, timeout=10)
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
    assert client.command(M.MAV_CMD_MISSION_START, 0, 0).result == M.MAV_RESULT_ACCEPTED
    client.wait_until(
        lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
        timeout=60,
        what="the end of the AUTO mission",
    )


@dataclass(frozen=True)
class Recorded:
    path: Path
    stdout: str
    sent_to_vehicle: int
    """Frames the vehicle received from the recorder's link (0: passive)."""


def start_record(args: list[str]) -> tuple[subprocess.Popen[str], str]:
    """``uavtool record ARGS`` in a process of its own, once it says it is recording, and
    what it said until then (kill it when done)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "uavtool", "record", *args],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    said = []
    while "recording to" not in (line := proc.stderr.readline()):
        if not line:
            proc.kill()
            raise AssertionError(f"record exited early: {said} {proc.communicate()}")
        said.append(line)
    return proc, "".join(said)


def record_auto_flight(path: Path) -> Recorded:
    """``uavtool record --camera sim --scene paper --until-landed`` (passive, on UDP) while a
    scripted ground station flies the AUTO mission over TCP: ~10 s of wall time."""
    scene = load_scene("paper")
    port = free_udp_port()
    counter = LinkCounter()
    endpoints = ("tcpin:127.0.0.1:0", f"udpout:127.0.0.1:{port}")
    with vehicle(scene, endpoints=endpoints, tap=counter) as sitl:
        args = [
            *("--connect", f"udpin:127.0.0.1:{port}", "-o", str(path)),
            *("--camera", "sim", "--scene", "paper", "--rate", "0.5", "--until-landed"),
        ]
        proc, _ = start_record(args)
        try:
            client = Client.tcp(sitl.ports[0])
            client.heartbeat()
            fly_auto_mission(client, scene)
            stdout, stderr = proc.communicate(timeout=30)
            client.close()
        finally:
            proc.kill()
        assert proc.returncode == 0, stderr
        recorder_links = [name for name in counter.received if not name.startswith("tcp")]
        sent = sum(counter.received[name] for name in recorder_links)
    return Recorded(path, stdout, sent)
