from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.sitl.client import Client
from uavtool.sitl import Sitl, SitlConfig

MOUNT = (("MNT1_TYPE", 1.0),)
"""A servo mount at boot (ArduCopter's default, and the built-in vehicle's, has none)."""


@pytest.fixture
def vehicle() -> Iterator[Sitl]:
    """A fresh in-process vehicle with a mount on an ephemeral loopback TCP port, 20× real
    time."""
    config = SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20.0, params=MOUNT)
    with Sitl(config) as sitl:
        yield sitl
    assert sitl.error is None, f"vehicle thread died: {sitl.error!r}"


@pytest.fixture
def client(vehicle: Sitl) -> Iterator[Client]:
    c = Client.tcp(vehicle.ports[0])
    c.wait_for("HEARTBEAT")
    yield c
    c.close()
