"""``udpout`` to a vehicle that listens on UDP (``uavtool sitl --endpoint udpin:…``, a MAVLink
router's server port): the vehicle cannot know where to send until the ground station speaks,
so the link sends its heartbeat first."""

from __future__ import annotations

import pytest

from tests.link.sitl_process import sitl_udpin
from uavtool.errors import LinkError
from uavtool.link import VehicleLink, open_transport
from uavtool.mavlink import mavlink as M


def test_udpout_reaches_a_vehicle_listening_on_udp() -> None:
    with sitl_udpin(speedup=10.0) as port:
        link = VehicleLink(open_transport(f"udpout:127.0.0.1:{port}"))
        try:
            link.wait_vehicle(10.0)
            assert link.target_system == 1
            assert link.state.home is not None and link.state.position is not None
            assert link.state.heartbeat.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
        finally:
            link.close()


def test_without_announcing_a_listening_vehicle_is_never_heard() -> None:
    with sitl_udpin(speedup=10.0) as port:
        link = VehicleLink(open_transport(f"udpout:127.0.0.1:{port}"), announce=False)
        try:
            with pytest.raises(LinkError, match="no heartbeat from a vehicle in 1 s"):
                link.wait_vehicle(1.0)
        finally:
            link.close()
