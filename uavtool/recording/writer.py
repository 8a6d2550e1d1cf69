"""`RecordingWriter`: one thread-safe, crash-safe, deterministic MCAP writer per mission.

What is recorded lives here: topics, schemas, channels, per-channel sequence numbers, the
JSON view of MAVLink frames, one lock so several threads can share the writer. Where the
bytes go and how durably (1 s chunks written and fsynced by a background thread, failures) is
`RecordingSink`'s job; the MCAP bytes themselves are `McapEncoder`'s.

Determinism: the writer never reads a clock or a random source; every time comes from the
caller, so identical calls give a byte-identical file (the header names the uavtool and
mcap versions; `McapEncoder` writes the bytes mcap's own `Writer` would).
"""

from __future__ import annotations

import struct
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, BinaryIO

from mcap import __version__ as mcap_version

from uavtool import __version__
from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.recording import rawframe
from uavtool.recording.errors import RecordingError
from uavtool.recording.protocol import (
    TOOL_METADATA,
    check_metadata,
    check_topic,
    foxglove_module,
)
from uavtool.recording.schemas import (
    DEFAULT_DIALECT,
    JSON_ENCODING,
    JSONSCHEMA_ENCODING,
    MAVLINK_RAW,
    PROTOBUF_ENCODING,
    MavlinkDecoder,
    dumps,
    mavlink_schema,
    mavlink_topic,
)
from uavtool.recording.sink import RecordingSink
from uavtool.recording.topics import FIX, POSE
from uavtool.recording.values import Direction, LocationFix, PosesInFrame

if TYPE_CHECKING:
    from uavtool.recording.foxglove import FoxgloveValue

# mcap's Writer names itself so (its LIBRARY_IDENTIFIER); importing mcap.writer for the name
# alone costs ~15 ms (the file is written by McapEncoder)
LIBRARY = f"uavtool/{__version__}; mcap-python/{mcap_version}"


class RecordingWriter:
    """Writes one recording. Use as a context manager; safe to share between threads.

    ``metadata`` maps record names (``mission``, ``scene``, ``seeds``, ``flight`` …) to
    string key/value pairs, written first after a ``uavtool`` record (tool version, dialect).
    ``file``: the file already opened for ``path`` (binary, written from its start), which the
    writer then owns; by default it creates ``path``.
    Every ``write_*`` takes ``log_time_ns`` (receive time, > 0, one epoch per file) and
    optionally ``publish_time_ns`` (defaults to the log time). Raises
    `ValueError` on misuse (time ≤ 0, unregistered topic, NaN in JSON, writing after close)
    and `RecordingError` once a write or fsync has failed (disk full, I/O error).
    """

    def __init__(
        self,
        path: str | Path,
        *,
        metadata: Mapping[str, Mapping[str, str]] | None = None,
        dialect: str = DEFAULT_DIALECT,
        chunk_interval_ns: int = 1_000_000_000,
        chunk_bytes: int = 1 << 20,
        fsync: bool = True,
        file: BinaryIO | None = None,
    ) -> None:
        self._decoder = MavlinkDecoder(dialect)  # checks the dialect before creating a file
        for name, record in (metadata or {}).items():
            check_metadata(name, record)
        self.dialect = dialect
        self.path = Path(path)
        self._lock = threading.Lock()
        self._closed = False
        self._message_count = 0
        self._schemas: dict[tuple[str, bytes], int] = {}
        self._channels: dict[str, int] = {}  # topic -> channel id
        # MAVLink message id -> its JSON channel's id, one dict per direction (an Enum key
        # hashes in Python: a tenth of the time of a write)
        self._mavlink_in: dict[int, int] = {}
        self._mavlink_out: dict[int, int] = {}
        self._raw_id = 0  # /mavlink/raw's channel id once it has one
        self._topic_kind: dict[str, Any] = {}  # topic -> value type or JSON schema name
        self._json_topics: dict[str, int] = {}  # topic -> channel id
        self._protobuf_schema: dict[str, str] = {}  # topic -> its Protobuf schema's name
        self._vehicle: Any = None  # foxglove.VehicleEncoder, once write_vehicle is called
        self._sequence: list[int] = [0]  # channel id -> its next sequence number
        tool = {"version": __version__, "dialect": dialect, "mavlink": "2.0"}
        self._sink = RecordingSink(
            self.path,
            library=LIBRARY,
            metadata=[(TOOL_METADATA, tool), *(metadata or {}).items()],
            interval_ns=chunk_interval_ns,
            budget_bytes=chunk_bytes,
            fsync=fsync,
            file=file,
        )

    # --- lifecycle ---------------------------------------------------------------------------

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        try:
            self.close()
        except RecordingError:
            # the failure already propagating from a write says the same: do not mask it
            if not (isinstance(exc, RecordingError) and exc.path == str(self.path)):
                raise

    @property
    def message_count(self) -> int:
        return self._message_count

    def flush(self) -> None:
        """Close the open chunk, hand it to the OS and (with ``fsync``) wait until it is on
        disk, e.g. before a long pause. Other threads keep writing meanwhile."""
        with self._lock:
            self._check_open()
            self._sink.close_chunk()
        self._sink.wait_synced()

    def hand_off(self) -> None:
        """Nothing to do: every call is written as it is made (`MessageWriter.hand_off`)."""

    def close(self) -> None:
        """Wait for the chunks still being written, write the last one and the summary
        (indexes, statistics), fsync the file and close it. Idempotent. Raises
        `RecordingError` if any write or fsync failed: the file is then not whole
        (`uavtool info --recover` rescues what it holds)."""
        with self._lock:
            if not self._closed:
                self._closed = True
                self._sink.close()

    # --- metadata and channels ---------------------------------------------------------------

    def add_metadata(self, name: str, record: Mapping[str, str]) -> None:
        """Add a named metadata record (e.g. the mission outcome at the end)."""
        check_metadata(name, record)
        with self._lock:
            self._check_open()
            self._sink.add_metadata(name, dict(record))

    def add_json_topic(self, topic: str, *, schema_name: str, schema: Mapping[str, Any]) -> None:
        """Declare a JSON topic with its JSON schema; `write_json` then writes to it."""
        check_topic(topic)
        with self._lock:
            self._check_open()
            known = self._topic_kind.get(topic)
            if known is not None:
                if known != schema_name:
                    raise ValueError(f"topic {topic!r} already carries {known!r}")
                return
            schema_id = self._schema(schema_name, JSONSCHEMA_ENCODING, dumps(schema))
            self._json_topics[topic] = self._channel(topic, topic, JSON_ENCODING, schema_id)
            self._topic_kind[topic] = schema_name

    # --- writes ------------------------------------------------------------------------------

    def write_json(
        self,
        topic: str,
        payload: Mapping[str, Any],
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        """Write a dict to a topic declared with `add_json_topic`."""
        try:
            data = dumps(payload)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"topic {topic!r}: payload is not JSON: {exc}") from exc
        self.write_json_bytes(topic, data, log_time_ns=log_time_ns, publish_time_ns=publish_time_ns)

    def write_json_bytes(
        self,
        topic: str,
        data: bytes,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        """Write a JSON object already encoded as `dumps` writes it (compact UTF-8, no NaN)
        to a topic declared with `add_json_topic`: for a caller that makes the bytes faster
        than a dict and `json` would. The bytes are not checked."""
        with self._lock:
            self._check_open()
            channel_id = self._json_topics.get(topic)
            if channel_id is None:
                raise ValueError(f"topic {topic!r} is not a JSON topic: call add_json_topic first")
            self._add(channel_id, log_time_ns, publish_time_ns, data)

    def write_json_format(
        self, topic: str, template: str, values: tuple[Any, ...], *, log_time_ns: int
    ) -> None:
        """`write_json_bytes` of ``(template % values).encode()`` (see `MessageWriter`)."""
        self.write_json_bytes(topic, (template % values).encode(), log_time_ns=log_time_ns)

    def write(
        self,
        topic: str,
        value: FoxgloveValue,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        """Write an image, calibration, transform, fix, poses, log entry or model (Foxglove)."""
        check_topic(topic)
        data = foxglove_module().encode(value, log_time_ns)
        self._write_foxglove(topic, type(value), data, log_time_ns, publish_time_ns)

    def write_vehicle(
        self,
        pos_enu_m: tuple[float, float, float],
        heading_deg: float,
        origin: GeoPoint | None,
        *,
        log_time_ns: int,
    ) -> None:
        """The vehicle's pose on ``/vehicle/pose`` and, when the local frame's ``origin`` is
        known, its WGS-84 fix on ``/vehicle/fix`` (one of each per telemetry sample)."""
        encoder = self._vehicle
        if encoder is None:
            encoder = self._vehicle = foxglove_module().VehicleEncoder()
        data = encoder.pose(pos_enu_m, heading_deg, log_time_ns)
        self._write_foxglove(POSE, PosesInFrame, data, log_time_ns, None)
        if origin is not None:
            geo = geo_from_enu(origin, *pos_enu_m)
            data = encoder.fix(geo.lat_deg, geo.lon_deg, geo.alt_amsl_m, log_time_ns)
            self._write_foxglove(FIX, LocationFix, data, log_time_ns, None)

    def write_protobuf(
        self,
        topic: str,
        data: bytes,
        *,
        schema_name: str,
        schema: bytes,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        """Write a Protobuf message already encoded (``schema``: its FileDescriptorSet): the
        same record `write` makes of a value that encodes to ``data``."""
        with self._lock:
            self._check_open()
            channel_id = self._channels.get(topic)
            if channel_id is None:
                check_topic(topic)
                channel_id = self._protobuf_channel(topic, schema_name, schema_name, schema)
            elif self._protobuf_schema.get(topic) != schema_name:
                raise ValueError(
                    f"topic {topic!r} carries {self._topic_kind.get(topic)!r}, not {schema_name}"
                )
            self._add(channel_id, log_time_ns, publish_time_ns, data)

    def write_mavlink(
        self,
        frame: bytes,
        *,
        direction: Direction,
        log_time_ns: int,
        publish_time_ns: int | None = None,
        decoded: Any = None,
    ) -> None:
        """Write one whole MAVLink frame to ``/mavlink/raw`` (see `rawframe`) and, if it
        decodes, its JSON view to ``/mavlink/<in|out>/<MSGNAME>``. Unknown or corrupt frames
        are kept raw only. ``decoded``: the pymavlink message already decoded from exactly
        these bytes (a link's parser has done it); used when it is of this recording's
        dialect, which saves decoding the frame again."""
        frame = bytes(frame)
        raw = rawframe.encode(direction, frame)
        # the two messages' times and sequence numbers as _add checks and keeps them, here
        # inline: this runs for every frame (tens of thousands per flight)
        if type(log_time_ns) is not int or log_time_ns <= 0:
            raise ValueError(f"log_time_ns must be a positive int, got {log_time_ns!r}")
        publish = log_time_ns if publish_time_ns is None else publish_time_ns
        with self._lock:
            self._check_open()
            raw_id = self._raw_id or self._raw_channel()
            sequence, add = self._sequence, self._sink.add
            try:
                add(raw_id, sequence[raw_id], log_time_ns, publish, raw)
            except struct.error as exc:  # raised before anything was added
                raise ValueError(f"times must fit an unsigned 64-bit int: {exc}") from exc
            sequence[raw_id] += 1
            self._message_count += 1
            if decoded is not None and self._decoder.owns(decoded):
                view = self._decoder.json(decoded)
            else:
                view = self._decoder.decode_json(frame)
            if view is None:
                return
            msgid, msg_name, data = view
            channels = self._mavlink_in if direction is Direction.IN else self._mavlink_out
            channel_id = channels.get(msgid)
            if channel_id is None:
                channel_id = self._mavlink_channel(direction, msgid, msg_name)
                channels[msgid] = channel_id
            add(channel_id, sequence[channel_id], log_time_ns, publish, data)
            sequence[channel_id] += 1
            self._message_count += 1

    def mavlink_tap(
        self, clock_ns: Callable[[], int]
    ) -> Callable[[str, list[bytes], list[Any] | None], None]:
        """`write_mavlink` as a link's tap, the frames of each call stamped ``clock_ns()``."""
        directions = {"in": Direction.IN, "out": Direction.OUT}
        write = self.write_mavlink

        def tap(direction: str, frames: list[bytes], decoded: list[Any] | None) -> None:
            t, way = clock_ns(), directions[direction]
            for i, frame in enumerate(frames):
                msg = None if decoded is None else decoded[i]
                write(frame, direction=way, log_time_ns=t, decoded=msg)

        return tap

    # --- internals (called with the lock held) -----------------------------------------------

    def _raw_channel(self) -> int:
        schema_id = self._schema(rawframe.SCHEMA_NAME, PROTOBUF_ENCODING, rawframe.SCHEMA_DATA)
        meta = {"dialect": self.dialect}
        self._raw_id = self._channel(MAVLINK_RAW, MAVLINK_RAW, PROTOBUF_ENCODING, schema_id, meta)
        return self._raw_id

    def _write_foxglove(
        self, topic: str, kind: type, data: bytes, log_time_ns: int, publish_time_ns: int | None
    ) -> None:
        """Write ``data``, a value of type ``kind`` encoded by `foxglove.encode`."""
        with self._lock:
            self._check_open()
            channel_id = self._channels.get(topic)
            if channel_id is None:
                foxglove = foxglove_module()
                name, schema = foxglove.schema_name(kind), foxglove.schema_data(kind)
                channel_id = self._protobuf_channel(topic, kind, name, schema)
            elif (known := self._topic_kind.get(topic)) is not kind and (
                known != foxglove_module().schema_name(kind)  # opened by write_protobuf
            ):
                raise ValueError(f"topic {topic!r} carries {known!r}, not {kind}")
            self._add(channel_id, log_time_ns, publish_time_ns, data)

    def _protobuf_channel(self, topic: str, kind: Any, name: str, schema: bytes) -> int:
        schema_id = self._schema(name, PROTOBUF_ENCODING, schema)
        self._topic_kind[topic] = kind
        self._protobuf_schema[topic] = name
        return self._channel(topic, topic, PROTOBUF_ENCODING, schema_id)

    def _mavlink_channel(self, direction: Direction, msgid: int, msg_name: str) -> int:
        name, schema = mavlink_schema(self.dialect, msgid)
        schema_id = self._schema(name, JSONSCHEMA_ENCODING, schema)
        topic = mavlink_topic(direction, msg_name)
        self._topic_kind[topic] = name
        return self._channel(None, topic, JSON_ENCODING, schema_id)

    def _check_open(self) -> None:
        # a failed write or fsync is raised by the sink on the next write, metadata or flush
        if self._closed:
            raise ValueError(f"{self.path}: the recording is closed")

    def _schema(self, name: str, encoding: str, data: bytes) -> int:
        schema_id = self._schemas.get((name, data))
        if schema_id is None:
            schema_id = self._sink.register_schema(name, encoding, data)
            self._schemas[(name, data)] = schema_id
        return schema_id

    def _channel(
        self,
        key: str | None,
        topic: str,
        encoding: str,
        schema_id: int,
        meta: dict[str, str] | None = None,
    ) -> int:
        """A new channel, known by ``key`` in `_channels` unless None (a MAVLink JSON
        channel: the caller keeps it)."""
        channel_id = self._sink.register_channel(topic, encoding, schema_id, meta or {})
        if key is not None:
            self._channels[key] = channel_id
        self._sequence.append(0)
        assert len(self._sequence) == channel_id + 1
        return channel_id

    def _add(
        self, channel_id: int, log_time_ns: int, publish_time_ns: int | None, data: bytes
    ) -> None:
        if type(log_time_ns) is not int or log_time_ns <= 0:
            raise ValueError(f"log_time_ns must be a positive int, got {log_time_ns!r}")
        publish = log_time_ns if publish_time_ns is None else publish_time_ns
        sequence = self._sequence[channel_id]
        try:
            self._sink.add(channel_id, sequence, log_time_ns, publish, data)
        except struct.error as exc:  # raised before anything was added
            raise ValueError(f"times must fit an unsigned 64-bit int: {exc}") from exc
        self._sequence[channel_id] = sequence + 1
        self._message_count += 1
