"""``/mavlink/raw`` as a Protobuf message: one whole MAVLink frame and the way it went.

Why Protobuf: Foxglove and Lichtblick decode only the message encodings they know (json,
protobuf, ros1, cdr, flatbuffer) and report any other (our former ``mavlink``) as unsupported;
Rerun's MCAP importer decodes any Protobuf schema too. A JSON channel would carry the frame
as base64 (a third larger, and a decode on every read). The Protobuf form keeps the frame's
bytes verbatim behind a 3–4 byte prefix, so ``.tlog`` export and replay stay lossless and
fast, and one channel holds both directions in recorded order.

Message ``uavtool.MavlinkFrame``: ``direction`` (enum ``IN`` = 0 vehicle → ground station,
``OUT`` = 1) and ``frame`` (bytes: the frame as it crossed the link).
"""

from __future__ import annotations

from google.protobuf import descriptor_pb2  # type: ignore[import-untyped]

from uavtool.recording.values import Direction

SCHEMA_NAME = "uavtool.MavlinkFrame"
_DIRECTION_CODE = {Direction.IN: 0, Direction.OUT: 1}
_DIRECTIONS = {v: k for k, v in _DIRECTION_CODE.items()}
_TAG_DIRECTION = 0x08  # field 1, varint
_TAG_FRAME = 0x12  # field 2, length-delimited


def _descriptor_set() -> bytes:
    fdp = descriptor_pb2.FileDescriptorProto(
        name="uavtool/MavlinkFrame.proto", package="uavtool", syntax="proto3"
    )
    msg = fdp.message_type.add(name="MavlinkFrame")
    enum = msg.enum_type.add(name="Direction")
    enum.value.add(name="IN", number=0)
    enum.value.add(name="OUT", number=1)
    f = descriptor_pb2.FieldDescriptorProto
    msg.field.add(
        name="direction",
        number=1,
        type=f.TYPE_ENUM,
        type_name=".uavtool.MavlinkFrame.Direction",
        label=f.LABEL_OPTIONAL,
    )
    msg.field.add(name="frame", number=2, type=f.TYPE_BYTES, label=f.LABEL_OPTIONAL)
    fds = descriptor_pb2.FileDescriptorSet(file=[fdp])
    return bytes(fds.SerializeToString(deterministic=True))


SCHEMA_DATA = _descriptor_set()


def _varint(n: int) -> bytes:
    out = bytearray()
    while n >= 0x80:
        out.append((n & 0x7F) | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


def _head(direction: Direction, length: int) -> bytes:
    code = _DIRECTION_CODE[direction]
    head = bytes((_TAG_DIRECTION, code)) if code else b""
    return head + bytes((_TAG_FRAME,)) + _varint(length)


# what comes before a frame of each length up to the longest MAVLink frame (280 bytes)
_HEAD_IN = [_head(Direction.IN, n) for n in range(281)]
_HEAD_OUT = [_head(Direction.OUT, n) for n in range(281)]


def encode(direction: Direction, frame: bytes) -> bytes:
    """The Protobuf bytes of one frame (proto3: the default direction ``IN`` is not written)."""
    n = len(frame)
    if n <= 280:
        if direction is Direction.IN:
            return _HEAD_IN[n] + frame
        if direction is Direction.OUT:
            return _HEAD_OUT[n] + frame
    return _head(direction, n) + frame


def decode(data: bytes) -> tuple[Direction, bytes]:
    """``(direction, frame)`` of a message written by `encode`; `ValueError` if malformed."""
    direction, frame, pos = Direction.IN, b"", 0
    try:
        while pos < len(data):
            tag = data[pos]
            pos += 1
            if tag == _TAG_DIRECTION:
                direction = _DIRECTIONS[data[pos]]
                pos += 1
            elif tag == _TAG_FRAME:
                length, shift = 0, 0
                while True:
                    b = data[pos]
                    pos += 1
                    length |= (b & 0x7F) << shift
                    shift += 7
                    if b < 0x80:
                        break
                if pos + length > len(data):
                    raise ValueError("frame cut short")
                frame, pos = bytes(data[pos : pos + length]), pos + length
            else:
                raise ValueError(f"unexpected field tag {tag:#x}")
    except (IndexError, KeyError) as exc:
        raise ValueError(f"malformed {SCHEMA_NAME}: {exc}") from None
    return direction, frame
