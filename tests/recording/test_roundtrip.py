"""Writer -> reader round trips, determinism, interop with the stock mcap reader, threads."""

from __future__ import annotations

import json
import re
import threading
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from mcap_protobuf.schema import build_file_descriptor_set

from tests.recording.sample import OBS_SCHEMA, T0_NS, mavlink_frames, other_values, write_sample
from uavtool.recording import (
    CompressedImage,
    Direction,
    JsonDocument,
    MavlinkFrame,
    RecordingReader,
    RecordingWriter,
    TopicNotFoundError,
    UnknownSchemaError,
    foxglove,
)
from uavtool.recording.schemas import dialect_module, mavlink_schema


def test_every_kind_round_trips(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    written = write_sample(path, seconds=1.0)
    with RecordingReader(path) as reader:
        entries = list(reader.entries())
        assert reader.health.whole
        assert len(entries) == written
        raw = [e.value for e in entries if e.topic == "/mavlink/raw"]
        assert raw == [MavlinkFrame(d, f) for d, f in mavlink_frames(100)]
        first = {e.topic: e.value for e in reversed(entries)}
        for topic, value in other_values():
            assert first[topic] == value, topic
        assert first["/mission/observations"] == JsonDocument(
            "test.Observation", {"step": 0, "alt_m": 45.0}
        )
        metadata = dict(reader.metadata)
        assert metadata["mission"] == {"target": "red", "alt_m": "45"}
        assert metadata["uavtool"]["dialect"] == "ardupilotmega"


def test_decoded_mavlink_is_json_with_nan_left_out(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    write_sample(path, seconds=0.1)
    with RecordingReader(path) as reader:
        cmd = next(reader.entries(["/mavlink/out/COMMAND_LONG"]))
        att = next(reader.entries(["/mavlink/in/ATTITUDE"]))
        text = next(reader.entries(["/mavlink/in/STATUSTEXT"]))
    assert isinstance(cmd.value, JsonDocument)
    assert cmd.value.schema_name == "ardupilotmega.COMMAND_LONG"
    assert cmd.value.payload["header"] == {"sysid": 255, "compid": 190, "seq": 0}
    assert cmd.value.payload["command"] == 115
    assert cmd.value.payload["param1"] == 90.0
    assert "param5" not in cmd.value.payload  # NaN on the wire: no value, no field
    assert isinstance(att.value, JsonDocument)
    assert att.value.payload["yaw"] == pytest.approx(1.0471975, rel=1e-6)
    assert isinstance(text.value, JsonDocument)
    assert text.value.payload["text"] == "step 4"
    assert cmd.publish_time_ns == 3 * 10_000_000 + 1  # vehicle time kept apart from log time


def test_every_dialect_message_has_a_valid_schema() -> None:
    module = dialect_module("ardupilotmega")
    for msgid, cls in module.mavlink_map.items():
        name, data = mavlink_schema("ardupilotmega", msgid)
        schema = json.loads(data)
        assert name == f"ardupilotmega.{cls.msgname}"
        assert set(schema["properties"]) == {"header", *cls.fieldnames}


def test_identical_input_gives_identical_bytes(tmp_path: Path) -> None:
    write_sample(tmp_path / "a.mcap", seconds=1.0)
    write_sample(tmp_path / "b.mcap", seconds=1.0)
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


def test_stock_mcap_reader_reads_it(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    written = write_sample(path, seconds=1.0)
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        assert summary.statistics is not None
        assert summary.statistics.message_count == written
        images = list(reader.iter_decoded_messages(topics=["/camera/image"]))
    assert images[0][3].data == other_values()[0][1].data  # type: ignore[attr-defined]
    assert images[0][3].timestamp.seconds == T0_NS // 1_000_000_000


def test_topics_and_time_range_filter(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    write_sample(path, seconds=3.0, chunk_interval_ns=500_000_000)
    with RecordingReader(path) as reader:
        lo, hi = T0_NS + 1_000_000_000, T0_NS + 2_000_000_000
        times = [m.log_time_ns for m in reader.messages(["/mavlink/raw"], start_ns=lo, end_ns=hi)]
        assert len(times) == 100
        assert min(times) == lo
        assert max(times) < hi
        seqs = [m.sequence for m in reader.messages(["/camera/image"])]
        assert seqs == [0, 1, 2]
        with pytest.raises(TopicNotFoundError, match="no topic '/nope'"):
            reader.messages(["/nope"])


def test_two_threads_share_a_writer_without_loss_or_reordering(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    n = 2000
    frames = mavlink_frames(n)

    with RecordingWriter(path, fsync=False) as writer:
        writer.add_json_topic("/runner", schema_name="t.Step", schema=OBS_SCHEMA)

        def sitl() -> None:
            for i, (direction, frame) in enumerate(frames):
                writer.write_mavlink(frame, direction=direction, log_time_ns=T0_NS + i)

        def runner() -> None:
            for i in range(n):
                writer.write_json("/runner", {"step": i}, log_time_ns=T0_NS + i)

        threads = [threading.Thread(target=sitl), threading.Thread(target=runner)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    with RecordingReader(path) as reader:
        steps = [m.data for m in reader.messages(["/runner"])]
        raw = [reader.decode(m).data for m in reader.messages(["/mavlink/raw"])]  # type: ignore[union-attr]
    assert steps == [json.dumps({"step": i}).replace(" ", "").encode() for i in range(n)]
    assert raw == [f for _, f in frames]


def test_writer_rejects_misuse(tmp_path: Path) -> None:
    with RecordingWriter(tmp_path / "rec.mcap", fsync=False) as writer:
        with pytest.raises(ValueError, match="positive"):
            writer.write("/camera/image", CompressedImage(b"x"), log_time_ns=0)
        with pytest.raises(ValueError, match="add_json_topic"):
            writer.write_json("/undeclared", {}, log_time_ns=1)
        writer.add_json_topic("/obs", schema_name="t.Obs", schema={})
        with pytest.raises(ValueError, match="not JSON"):
            writer.write_json("/obs", {"x": float("nan")}, log_time_ns=1)
        with pytest.raises(ValueError, match="/mavlink/"):
            writer.add_json_topic("/mavlink/in/FAKE", schema_name="x", schema={})
        with pytest.raises(ValueError, match="carries"):
            writer.write("/obs", CompressedImage(b"x"), log_time_ns=1)
    with pytest.raises(ValueError, match="closed"):
        writer.write("/camera/image", CompressedImage(b"x"), log_time_ns=1)


def test_corrupt_and_unknown_frames_stay_raw_only(tmp_path: Path) -> None:
    path = tmp_path / "rec.mcap"
    good = mavlink_frames(2)[1][1]
    bad_crc = good[:-1] + bytes([good[-1] ^ 0xFF])
    with RecordingWriter(path, fsync=False) as writer:
        writer.write_mavlink(bad_crc, direction=Direction.IN, log_time_ns=T0_NS)
        writer.write_mavlink(b"\x00garbage", direction=Direction.IN, log_time_ns=T0_NS + 1)
    with RecordingReader(path) as reader:
        assert reader.topics() == ["/mavlink/raw"]
        assert [e.value.data for e in reader.entries()] == [bad_crc, b"\x00garbage"]  # type: ignore[union-attr]


def test_unknown_schema_is_a_clear_error(tmp_path: Path) -> None:
    from mcap.writer import Writer

    path = tmp_path / "ros.mcap"
    with path.open("wb") as f:
        w = Writer(f)
        w.start()
        sid = w.register_schema("std_msgs/String", "ros1msg", b"string data")
        cid = w.register_channel("/chatter", "ros1", sid)
        w.add_message(cid, log_time=1, data=b"\x00\x00\x00\x00", publish_time=1)
        w.finish()
    with RecordingReader(path) as reader:
        message = next(reader.messages())
        with pytest.raises(
            UnknownSchemaError, match=re.escape("ros.mcap: topic '/chatter': cannot decode 'ros1'")
        ):
            reader.decode(message)


def test_files_without_a_summary_are_scanned(tmp_path: Path) -> None:
    from mcap.writer import IndexType, Writer

    path = tmp_path / "bare.mcap"
    with path.open("wb") as f:
        w = Writer(f, index_types=IndexType.NONE, repeat_channels=False, repeat_schemas=False)
        w.start()
        cid = w.register_channel("/mavlink/raw", "mavlink", 0, {"direction": "in"})
        for i, (_d, frame) in enumerate(mavlink_frames(10)):
            w.add_message(cid, log_time=i + 1, data=frame, publish_time=i + 1)
        w.finish()
    with RecordingReader(path) as reader:
        assert reader.health.whole
        assert not reader.health.indexed
        frames = [e.value for e in reader.entries(["/mavlink/raw"])]
    assert frames == [MavlinkFrame(Direction.IN, f) for _, f in mavlink_frames(10)]


def test_schemas_are_the_file_descriptor_sets_mcap_protobuf_builds() -> None:
    """`foxglove.file_descriptor_set` walks the descriptors itself (mcap_protobuf's module
    imports mcap's writer): the bytes must be mcap_protobuf's, for every schema written."""
    for value_type, pb_class in foxglove._PB_CLASS.items():
        theirs = build_file_descriptor_set(pb_class).SerializeToString(deterministic=True)
        assert foxglove.schema_data(value_type) == theirs, pb_class.DESCRIPTOR.full_name
        assert len(foxglove.FileDescriptorSet.FromString(theirs).file) > 1  # with its imports
