"""`McapEncoder` writes exactly the bytes of mcap's own `Writer` for the same calls."""

from __future__ import annotations

import io
import struct
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

from tests.recording.sample import OBS_SCHEMA, T0_NS
from uavtool import __version__
from uavtool.recording import RecordingWriter
from uavtool.recording.encoder import McapEncoder
from uavtool.recording.schemas import dumps
from uavtool.recording.writer import LIBRARY, TOOL_METADATA

Op = tuple[Any, ...]


def _ours(ops: list[Op]) -> bytes:
    out = io.BytesIO()
    enc = McapEncoder(out, library="lib/1")
    for kind, *args in ops:
        if kind == "meta":
            enc.add_metadata(*args)
        elif kind == "schema":
            enc.register_schema(*args)
        elif kind == "channel":
            enc.register_channel(*args)
        elif kind == "message":
            enc.add_message(*args)
        else:
            enc.close_chunk()
    enc.finish()
    return out.getvalue()


def _theirs(ops: list[Op]) -> bytes:
    out = io.BytesIO()
    w = Writer(out, chunk_size=1 << 62, compression=CompressionType.ZSTD, enable_data_crcs=True)
    w.start(profile="", library="lib/1")
    for kind, *args in ops:
        if kind == "meta":
            w.add_metadata(*args)
        elif kind == "schema":
            w.register_schema(name=args[0], encoding=args[1], data=args[2])
        elif kind == "channel":
            w.register_channel(args[0], args[1], args[2], args[3])
        elif kind == "message":
            cid, seq, log, pub, data = args
            w.add_message(cid, log_time=log, data=data, publish_time=pub, sequence=seq)
        else:
            w.flush()
    w.finish()
    return out.getvalue()


def test_a_mixed_file_is_byte_identical_to_mcap_writer() -> None:
    ops: list[Op] = [
        ("meta", "uavtool", {"version": "1", "é": "ü"}),
        ("schema", "t.Obs", "jsonschema", b"{}"),
        ("channel", "/obs", "json", 1, {}),
        ("close",),  # no message yet: the schema and channel stay in the open chunk
        ("channel", "/mavlink/raw", "mavlink", 0, {"direction": "in", "dialect": "x"}),
        ("message", 1, 0, 100, 100, b"hello"),
        ("message", 2, 0, 90, 5, b"\x00" * 3000),  # earlier log time than the one before
        ("message", 1, 1, 120, 7, b""),
        ("meta", "mid", {}),  # metadata goes out before the open chunk
        ("close",),
        ("close",),
        ("schema", "foxglove.Log", "protobuf", b"\x01\x02"),
        ("channel", "/log", "protobuf", 2, {"k": "v"}),
        ("message", 3, 0, 150, 150, b"zz"),
        ("message", 2, 1, 2**64 - 1, 0, b"y"),
    ]
    assert _ours(ops) == _theirs(ops)
    assert _ours([]) == _theirs([])


_messages = st.lists(
    st.tuples(
        st.integers(1, 3),  # channel
        st.integers(1, 2**40),  # log time
        st.binary(max_size=300),
        st.booleans(),  # close the chunk after it
    ),
    max_size=60,
)


@settings(max_examples=40, deadline=None)
@given(_messages)
def test_any_message_sequence_is_byte_identical_to_mcap_writer(
    messages: list[tuple[int, int, bytes, bool]],
) -> None:
    ops: list[Op] = [("schema", "s", "jsonschema", b"{}")]
    ops += [("channel", f"/c{c}", "json", 1, {"n": str(c)}) for c in (1, 2, 3)]
    for i, (channel, log_ns, data, close) in enumerate(messages):
        ops.append(("message", channel, i, log_ns, log_ns // 2, data))
        if close:
            ops.append(("close",))
    assert _ours(ops) == _theirs(ops)


def test_out_of_range_times_change_nothing() -> None:
    out = io.BytesIO()
    enc = McapEncoder(out, library="lib/1")
    enc.register_channel("/c", "json", 0, {})
    with pytest.raises(struct.error):
        enc.add_message(1, 0, 2**64, 1, b"x")
    enc.add_message(1, 0, 5, 5, b"x")
    enc.finish()
    ops: list[Op] = [("channel", "/c", "json", 0, {}), ("message", 1, 0, 5, 5, b"x")]
    assert out.getvalue() == _theirs(ops)


def test_recording_writer_file_equals_the_bare_mcap_writer_file(tmp_path: Path) -> None:
    """What the benchmark compares: our writer and a bare Writer chunking the same way."""
    path = tmp_path / "ours.mcap"
    with RecordingWriter(path, chunk_interval_ns=1000, fsync=False) as writer:
        writer.add_json_topic("/obs", schema_name="t.Obs", schema=OBS_SCHEMA)
        for i in range(50):
            writer.write_json("/obs", {"step": i}, log_time_ns=T0_NS + 300 * i)
    out = io.BytesIO()
    w = Writer(out, chunk_size=1 << 62, compression=CompressionType.ZSTD, enable_data_crcs=True)
    w.start(profile="", library=LIBRARY)
    w.add_metadata(
        TOOL_METADATA, {"version": __version__, "dialect": "ardupilotmega", "mavlink": "2.0"}
    )
    cid = w.register_channel(
        "/obs", "json", w.register_schema("t.Obs", "jsonschema", dumps(OBS_SCHEMA))
    )
    start = None
    for i in range(50):
        t = T0_NS + 300 * i
        w.add_message(cid, log_time=t, data=dumps({"step": i}), publish_time=t, sequence=i)
        start = t if start is None else start
        if t - start >= 1000:
            w.flush()
            start = None
    w.finish()
    assert path.read_bytes() == out.getvalue()


def test_the_header_names_mcaps_writer_as_it_names_itself() -> None:
    """The writer builds mcap's library name from mcap's version (its writer module is
    ~15 ms to import); it must be the very name mcap's Writer gives."""
    assert LIBRARY.endswith(f"; {LIBRARY_IDENTIFIER}")
