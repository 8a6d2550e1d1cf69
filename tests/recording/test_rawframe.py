"""``/mavlink/raw`` frames as ``uavtool.MavlinkFrame`` Protobuf: lossless, and the bytes are
what Protobuf itself writes for that schema."""

from __future__ import annotations

from typing import Any

import pytest
from google.protobuf import (  # type: ignore[import-untyped]
    descriptor_pb2,
    descriptor_pool,
    message_factory,
)
from hypothesis import given
from hypothesis import strategies as st

from uavtool.recording import rawframe
from uavtool.recording.values import Direction


def _protobuf_class() -> Any:
    fds = descriptor_pb2.FileDescriptorSet.FromString(rawframe.SCHEMA_DATA)
    pool = descriptor_pool.DescriptorPool()
    for f in fds.file:
        pool.Add(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(rawframe.SCHEMA_NAME))


@given(st.sampled_from(list(Direction)), st.binary(min_size=1, max_size=400))
def test_round_trip_and_matches_protobuf(direction: Direction, frame: bytes) -> None:
    data = rawframe.encode(direction, frame)
    assert rawframe.decode(data) == (direction, frame)
    cls = _protobuf_class()
    parsed = cls.FromString(data)
    assert parsed.frame == frame
    assert parsed.direction == (1 if direction is Direction.OUT else 0)
    assert cls(direction=parsed.direction, frame=frame).SerializeToString() == data


@pytest.mark.parametrize("data", [b"\x12\x05abc", b"\x08\x07\x12\x00", b"\x1a\x00"])
def test_malformed_is_a_value_error(data: bytes) -> None:
    with pytest.raises(ValueError, match=r"frame cut short|malformed|unexpected"):
        rawframe.decode(data)
