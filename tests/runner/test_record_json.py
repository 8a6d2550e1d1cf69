"""A telemetry sample's JSON as the flight records it (`telemetry_json`, one template) is byte
for byte what the general path writes (``dumps({"step": n, **encode_observation(t)})``): for
every sample of every golden, and for awkward values; anything the template cannot write
exactly (a numpy number, a NaN) is left to the general path."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from uavtool.mission import Telemetry
from uavtool.mission.codec import decode_observation, encode_observation
from uavtool.recording import RecordingReader
from uavtool.recording.fleet import split_topic
from uavtool.recording.schemas import dumps
from uavtool.recording.topics import OBSERVATIONS
from uavtool.runner.record import telemetry_json

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))


def _general(step: int, t: Telemetry) -> bytes:
    return dumps({"step": step, **encode_observation(t)})


@pytest.mark.parametrize("path", GOLDEN, ids=[p.name for p in GOLDEN])
def test_every_golden_sample(path: Path) -> None:
    n = 0
    with RecordingReader(path) as reader:
        # a fleet's observations are its vehicles' (/uavK/mission/observations)
        topics = {c.topic for c in reader.channels.values()}
        observations = sorted(t for t in topics if split_topic(t)[1] == OBSERVATIONS)
        for message in reader.messages(observations):
            data = json.loads(message.data)
            if data["type"] != "Telemetry":
                continue
            obs = decode_observation(data)
            assert isinstance(obs, Telemetry)
            made = telemetry_json(data["step"], obs)
            assert made is not None and made == _general(data["step"], obs) == message.data
            n += 1
    assert n > 1000


SAMPLE = Telemetry(
    12, (1.5, -0.0, 1e16), (1e-7, 2.0, -3.25), 359.9, "GUIDED", True, False, -90.0, 0.0, 87
)


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"mode": 'a"b\\c\n\x01é%s'},
        {"pos_enu_m": (0.1 + 0.2, 1 / 3, -2.5e-300)},
        {"armed": False, "landed": True, "battery_pct": -1},
    ],
)
def test_awkward_values_match_the_general_path(changes: dict[str, object]) -> None:
    t = dataclasses.replace(SAMPLE, **changes)  # type: ignore[arg-type]
    assert telemetry_json(7, t) == _general(7, t)


@pytest.mark.parametrize(
    "changes",
    [
        {"heading_deg": float("nan")},
        {"vel_enu_m_s": (0.0, float("inf"), 0.0)},
        {"pos_enu_m": (np.float64(1.5), 0.0, 0.0)},
        {"battery_pct": np.int64(50)},
        {"armed": 1},
        {"pos_enu_m": (1.0, 2.0)},
    ],
)
def test_what_the_template_cannot_write_goes_the_general_way(changes: dict[str, object]) -> None:
    assert telemetry_json(7, dataclasses.replace(SAMPLE, **changes)) is None  # type: ignore[arg-type]
