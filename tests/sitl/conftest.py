from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.sitl.client import Client
from uavtool.sitl import Sitl, SitlConfig


@pytest.fixture
def vehicle() -> Iterator[Sitl]:
    """A fresh in-process vehicle on an ephemeral loopback TCP port, 20× real time."""
    with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20.0)) as sitl:
        yield sitl
    assert sitl.error is None, f"vehicle thread died: {sitl.error!r}"


@pytest.fixture
def client(vehicle: Sitl) -> Iterator[Client]:
    c = Client.tcp(vehicle.ports[0])
    c.wait_for("HEARTBEAT")
    yield c
    c.close()
