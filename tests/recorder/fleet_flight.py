"""A fleet someone else flies, for the recorder's tests: built-in vehicles in one world
(`uavtool.sitl.fleet.Fleet`), 10 m apart on a line to the east over the paper scene, each
sending its telemetry to one UDP port (as a radio or a router carries a fleet) and flown by a
scripted ground station of its own over TCP: GUIDED take-off, a hop north, LAND."""

from __future__ import annotations

import dataclasses
import math
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from tests.recorder.flight import free_udp_port
from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.mavlink.dialect import COPTER_MODES
from uavtool.sitl import SitlConfig
from uavtool.sitl.fleet import Fleet, OffsetLine, fleet_configs, line_homes
from uavtool.sitl.links import FrameTap
from uavtool.world import load_scene

SPACING_M = 10.0
SPEEDUP = 8.0


def altitude_m(sysid: int) -> float:
    """Each vehicle climbs to a height of its own: 3 m, 4 m, 5 m …"""
    return 2.0 + sysid


@dataclasses.dataclass
class SharedPortFleet:
    fleet: Fleet
    port: int
    """The UDP port every vehicle sends to: the recorder's ``udpin``."""


@contextmanager
def shared_port_fleet(
    count: int,
    *,
    port: int | None = None,
    tap: FrameTap | None = None,
    silent_from_s: dict[int, float] | None = None,
) -> Iterator[SharedPortFleet]:
    """``count`` vehicles (system ids 1 …) served in a thread, each on a TCP port of its own
    for its pilot and all sending to ``port``; ``tap`` hears every vehicle's frames;
    ``silent_from_s``: vehicle (system id) → sim time from which its links are cut for good."""
    silent = silent_from_s or {}
    port = free_udp_port() if port is None else port
    scene = load_scene("paper")
    base = SitlConfig(endpoints=(), speedup=SPEEDUP, home=scene.home)
    homes = line_homes(scene.home, count, OffsetLine(90.0, SPACING_M))
    configs = tuple(
        # Vehicle i's endpoints move by 10·i ports (as ArduPilot's -I): this one lands on `port`.
        dataclasses.replace(
            c,
            endpoints=("tcpin:127.0.0.1:0", f"udpout:127.0.0.1:{port - 10 * c.instance}"),
            link_outages_s=((silent[c.instance + 1], 1e6),) if c.instance + 1 in silent else (),
        )
        for c in fleet_configs(base, homes)
    )
    with Fleet(configs, frame_tap=tap) as fleet:
        yield SharedPortFleet(fleet, port)


def fly(client: Client, sysid: int) -> None:
    """GUIDED take-off to `altitude_m`, a hop of 3 m north, LAND until disarmed."""
    target = (sysid, 1)
    client.heartbeat()
    client.wait_until(lambda c: "GLOBAL_POSITION_INT" in c.latest, 10, "telemetry")
    mode = client.command(M.MAV_CMD_DO_SET_MODE, 1, COPTER_MODES["GUIDED"], target=target)
    assert mode.result == M.MAV_RESULT_ACCEPTED
    arm = client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1, target=target)
    assert arm.result == M.MAV_RESULT_ACCEPTED
    alt = altitude_m(sysid)
    up = client.command(M.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, math.nan, 0, 0, alt, target=target)
    assert up.result == M.MAV_RESULT_ACCEPTED
    client.wait_until(lambda c: c.alt_m() > alt - 0.3, 30, f"vehicle {sysid} at {alt} m")
    here = client.latest["GLOBAL_POSITION_INT"]
    north = here.lat + round(3.0 / 111_319.5 * 1e7)
    client.send(
        M.MAVLink_set_position_target_global_int_message(
            0, sysid, 1, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, 0b110111111000,
            north, here.lon, alt, 0, 0, 0, 0, 0, 0, 0, 0,
        )
    )  # fmt: skip
    client.wait_until(
        lambda c: c.latest["GLOBAL_POSITION_INT"].lat > north - 5, 30, f"vehicle {sysid} north"
    )
    land = client.command(M.MAV_CMD_DO_SET_MODE, 1, COPTER_MODES["LAND"], target=target)
    assert land.result == M.MAV_RESULT_ACCEPTED
    client.wait_until(
        lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
        60,
        f"vehicle {sysid} landed and disarmed",
    )


def fly_all(fleet: Fleet, sysids: list[int] | None = None) -> None:
    """Fly every vehicle of ``fleet`` (or those of ``sysids``) at once, a pilot each."""
    errors: list[BaseException] = []
    chosen = [v for v in fleet.vehicles if sysids is None or v.sysid in sysids]

    def pilot(port: int, sysid: int) -> None:
        client = Client.tcp(port)
        try:
            fly(client, sysid)
        except BaseException as exc:  # re-raised in the test's thread
            errors.append(exc)
        finally:
            client.close()

    threads = [
        threading.Thread(target=pilot, args=(v.ports[0], v.sysid), name=f"pilot-{v.sysid}")
        for v in chosen
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
