"""Replay's foundations: the mission is a pure function of what it observed, and every
observation survives the codec (dict → JSON → dict) exactly."""

from __future__ import annotations

import dataclasses
import json
import struct
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.mission.driver import At, Flown, LinkOutage, fly
from uavtool.camera import CameraPose, Intrinsics
from uavtool.mission import (
    CommandResult,
    LinkLost,
    LinkRestored,
    MissionInputError,
    MissionInputs,
    Observation,
    Output,
    Photo,
    Plan,
    SearchMission,
    Telemetry,
)
from uavtool.mission.codec import decode_observation, encode_observation, encode_output
from uavtool.world import Scene


@pytest.fixture(scope="module")
def troubled_flight(paper: Scene) -> Flown:
    """A flight with refusals, a lost ACK and a link outage in its observations."""
    outage = LinkOutage(At(after=Plan), 6.0)
    return fly(paper, refuse={"SetGimbal": 2}, ignore={"Takeoff": 1}, script=(outage,))


def _through_json(obs: Observation) -> Observation:
    text = json.dumps(encode_observation(obs), allow_nan=False)
    image = obs.image_rgb if isinstance(obs, Photo) else None
    return decode_observation(json.loads(text), image)


def _bits(value: Any) -> Any:
    """Floats as their IEEE bits (so −0.0 ≠ 0.0), recursively through tuples."""
    if isinstance(value, float):
        return struct.pack("<d", value)
    if isinstance(value, tuple):
        return tuple(_bits(v) for v in value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__, _bits(dataclasses.astuple(value)))
    return value


def _assert_same(a: Observation, b: Observation) -> None:
    assert type(a) is type(b)
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y)
        else:
            assert _bits(x) == _bits(y), f.name
            assert type(x) is type(y), f.name


def _encoded(outputs: list[Output]) -> list[dict[str, Any]]:
    return [encode_output(o) for o in outputs]


@pytest.mark.parametrize(
    "flight_name", ["paper_flight", "visit_all_flight", "troubled_flight", "turned_flight"]
)
def test_replaying_the_observations_reproduces_every_output(
    flight_name: str, request: pytest.FixtureRequest
) -> None:
    """Two fresh missions, stepped in turn on the decoded observations, say exactly what the
    flown one said (no hidden state shared between missions, nothing but observations read)."""
    flown: Flown = request.getfixturevalue(flight_name)
    params = flown.mission.params
    inputs = MissionInputs(flown.target_rgb)
    first, second = SearchMission(params, inputs), SearchMission(params, inputs)
    out1, out2 = first.start(), second.start()
    for obs in flown.flight.observations:
        decoded = _through_json(obs)
        out1 += first.step(decoded)
        out2 += second.step(decoded)
    expected = _encoded(flown.flight.outputs)
    assert _encoded(out1) == expected
    assert _encoded(out2) == expected
    assert first.outcome == flown.mission.outcome


def test_a_replay_that_stops_early_is_a_prefix(troubled_flight: Flown) -> None:
    flown = troubled_flight
    mission = SearchMission(flown.mission.params, MissionInputs(flown.target_rgb))
    outputs = mission.start()
    half = len(flown.flight.observations) // 2
    for obs in flown.flight.observations[:half]:
        outputs += mission.step(obs)
    assert mission.outcome is None
    assert _encoded(outputs) == _encoded(flown.flight.outputs)[: len(outputs)]


def test_every_observation_of_a_flight_round_trips(troubled_flight: Flown) -> None:
    kinds = set()
    for obs in troubled_flight.flight.observations:
        _assert_same(_through_json(obs), obs)
        kinds.add(type(obs))
    assert kinds == {Telemetry, CommandResult, Photo, LinkLost, LinkRestored}


_finite = st.floats(allow_nan=False, allow_infinity=False)
_vec3 = st.tuples(_finite, _finite, _finite)


@given(
    st.builds(
        Telemetry,
        time_boot_ms=st.integers(0, 2**32 - 1),
        pos_enu_m=_vec3,
        vel_enu_m_s=_vec3,
        heading_deg=_finite,
        mode=st.sampled_from(["GUIDED", "RTL", "LAND", "LOITER", "MODE99"]),
        armed=st.booleans(),
        landed=st.booleans(),
        gimbal_pitch_deg=_finite,
        gimbal_yaw_deg=_finite,
        battery_pct=st.integers(-1, 100),
    )
)
def test_telemetry_round_trips_bit_for_bit(t: Telemetry) -> None:
    _assert_same(_through_json(t), t)


@given(
    st.one_of(
        st.builds(
            CommandResult,
            st.integers(1, 2**31),
            st.booleans(),
            st.text(max_size=40),
            st.booleans(),
        ),
        st.builds(LinkLost, _finite),
        st.builds(LinkRestored, _finite),
    )
)
def test_small_observations_round_trip(obs: Observation) -> None:
    _assert_same(_through_json(obs), obs)


@given(_vec3, _finite, _finite, st.integers(1, 4096), st.integers(1, 4096), _finite, _finite)
def test_photo_pose_and_intrinsics_round_trip(
    pos: tuple[float, float, float],
    heading: float,
    pitch: float,
    w: int,
    h: int,
    f: float,
    c: float,
) -> None:
    image = np.zeros((2, 3, 3), dtype=np.uint8)
    photo = Photo(
        7, 3, "poi-1", 1234, CameraPose(pos, heading, pitch), Intrinsics(w, h, f, f, c, c), image
    )
    decoded = _through_json(photo)
    _assert_same(decoded, photo)
    assert isinstance(decoded, Photo) and decoded.image_rgb is image


def test_malformed_observations_are_input_errors() -> None:
    good = encode_observation(
        Telemetry(1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.0, "GUIDED", True, False, 0.0, 0.0, 90)
    )
    missing = {k: v for k, v in good.items() if k != "heading_deg"}
    with pytest.raises(MissionInputError, match="heading_deg"):
        decode_observation(missing)
    with pytest.raises(MissionInputError, match="unknown observation type 'Teleport'"):
        decode_observation({**good, "type": "Teleport"})
    photo = Photo(
        1,
        0,
        "overview",
        5,
        CameraPose((0.0, 0.0, 45.0), 0.0, -90.0),
        Intrinsics.from_hfov(),
        np.zeros((1, 1, 3), np.uint8),
    )
    with pytest.raises(MissionInputError, match="image is missing"):
        decode_observation(encode_observation(photo))


def test_a_command_result_recorded_before_final_existed_is_not_final() -> None:
    """Recordings made before `CommandResult.final` have no such field: a refusal in them
    replays as one the mission asked again after, as it did when it was flown."""
    old = {"type": "CommandResult", "action_id": 7, "accepted": False, "detail": "refused"}
    assert decode_observation(old) == CommandResult(7, False, "refused", final=False)
