"""Topic names, channel encodings and the JSON view of MAVLink messages.

Every decoded MAVLink message type gets its own JSON schema, generated from pymavlink's
message definitions (field types, array lengths, units, enums, the message description), so
Foxglove and Lichtblick list and plot every field.

The rule for JSON channels (`NULL_RULE`): each field has exactly one JSON type — the one its
values have — because Foxglove's and Lichtblick's schema parsers reject a list of types such
as ``["number", "null"]`` and then drop the whole channel. A value that is absent or not
finite (MAVLink's "NaN = unchanged", ±∞, an unset optional) is left out of the message, and
the schema does not require it: JSON has no NaN, a standard JSON Schema validator rejects
``null`` for a number, those viewers show a missing field as "no value" (a gap in a plot), and
the exact bytes stay in the raw frame. An array with any such element is left out whole.
"""

from __future__ import annotations

import importlib
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from operator import attrgetter
from types import ModuleType
from typing import Any, cast

from uavtool.recording.values import Direction

# --- topics ---------------------------------------------------------------------------------

MAVLINK_RAW = "/mavlink/raw"
CAMERA_IMAGE = "/camera/image"
CAMERA_CALIBRATION = "/camera/calibration"
CAMERA_POSE = "/camera/pose"
VEHICLE_FIX = "/vehicle/fix"
VEHICLE_POSE = "/vehicle/pose"
MISSION_EVENTS = "/mission/events"
MISSION_MODEL = "/mission/model"


def mavlink_topic(direction: Direction, msg_name: str) -> str:
    """``/mavlink/in/HEARTBEAT``: the decoded-JSON channel of one message type and direction."""
    return f"/mavlink/{direction.value}/{msg_name}"


# --- encodings ------------------------------------------------------------------------------

MAVLINK_ENCODING = "mavlink"  # message data = one whole MAVLink frame, as on the wire
JSON_ENCODING = "json"
JSONSCHEMA_ENCODING = "jsonschema"
PROTOBUF_ENCODING = "protobuf"
DEFAULT_DIALECT = "ardupilotmega"

_JSON = json.JSONEncoder(ensure_ascii=False, allow_nan=False, separators=(",", ":"))


def dumps(obj: Any) -> bytes:
    """Compact, deterministic UTF-8 JSON; `ValueError` on NaN/Infinity (JSON has none)."""
    return _JSON.encode(obj).encode()


# --- MAVLink --------------------------------------------------------------------------------

_INT_TYPES = {
    "int8_t",
    "uint8_t",
    "int16_t",
    "uint16_t",
    "int32_t",
    "uint32_t",
    "int64_t",
    "uint64_t",
}
_FLOAT_TYPES = {"float", "double"}
NULL_RULE = "absent: no value (not finite)"

_HEADER_SCHEMA = {
    "type": "object",
    "description": "MAVLink frame header",
    "properties": {
        "sysid": {"type": "integer", "description": "sender system id"},
        "compid": {"type": "integer", "description": "sender component id"},
        "seq": {"type": "integer", "description": "link sequence number"},
    },
}


@cache
def dialect_module(dialect: str) -> ModuleType:
    """pymavlink's MAVLink 2 module of ``dialect`` (``ardupilotmega``); `ValueError` if none."""
    if not dialect.isidentifier():
        raise ValueError(f"not a MAVLink dialect name: {dialect!r}")
    try:
        return importlib.import_module(f"pymavlink.dialects.v20.{dialect}")
    except ImportError as exc:
        raise ValueError(f"pymavlink has no MAVLink 2 dialect {dialect!r}") from exc


def _field_schema(
    field_type: str, length: int, units: str, enum: str, display: str
) -> dict[str, Any]:
    base = field_type.split("[", maxsplit=1)[0]
    item: dict[str, Any]
    if base == "char":
        item = {"type": "string"}
    elif base in _FLOAT_TYPES:
        item = {"type": "number"}
    elif base in _INT_TYPES:
        item = {"type": "integer"}
    else:  # pragma: no cover - every MAVLink wire type is listed above
        raise ValueError(f"unknown MAVLink field type {field_type!r}")
    notes = [f"{base}"] if base not in _FLOAT_TYPES else [f"{base}", NULL_RULE]
    if units:
        notes.append(f"units: {units}")
    if enum:
        notes.append(f"enum: {enum}")
    if display:
        notes.append(display)
    if length and base != "char":
        return {"type": "array", "items": item, "maxItems": length, "description": ", ".join(notes)}
    return {**item, "description": ", ".join(notes)}


@cache
def mavlink_schema(dialect: str, msgid: int) -> tuple[str, bytes]:
    """Schema name (``ardupilotmega.HEARTBEAT``) and JSON schema bytes of one message type."""
    cls = dialect_module(dialect).mavlink_map[msgid]
    properties: dict[str, Any] = {"header": _HEADER_SCHEMA}
    for name, ftype, length in _fields(cls):
        properties[name] = _field_schema(
            ftype,
            length,
            cls.fieldunits_by_name.get(name, ""),
            cls.fieldenums_by_name.get(name, ""),
            cls.fielddisplays_by_name.get(name, ""),
        )
    description = " ".join((cls.__doc__ or "").split())
    schema = {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": f"{dialect}.{cls.msgname}",
        "description": f"MAVLink message {cls.msgname} (id {msgid}). {description}".strip(),
        "type": "object",
        "properties": properties,
        # A float may be NaN ("unchanged"), hence absent: only the others are always there.
        "required": ["header", *(n for n, t, _ in _fields(cls) if t not in _FLOAT_TYPES)],
    }
    return f"{dialect}.{cls.msgname}", dumps(schema)


_PLAIN, _FLOAT, _FLOATS = 0, 1, 2


@cache
def _view_fields(dialect: str, msgid: int) -> tuple[tuple[str, int], ...]:
    """Each field of a message type in declaration order, with how its JSON view is made:
    as it is (text for char fields), a float (absent when not finite), floats (absent when
    any is not finite)."""
    cls = dialect_module(dialect).mavlink_map[msgid]
    return tuple(
        (name, (_FLOATS if length else _FLOAT) if ftype in _FLOAT_TYPES else _PLAIN)
        for name, ftype, length in _fields(cls)
    )


def _fields(cls: Any) -> list[tuple[str, str, int]]:
    """``(name, type, array length)`` of each field in declaration order. pymavlink keeps
    ``array_lengths`` in wire order (``ordered_fieldnames``), not in ``fieldnames`` order."""
    lengths = dict(zip(cls.ordered_fieldnames, cls.array_lengths, strict=True))
    return [
        (name, ftype, lengths[name])
        for name, ftype in zip(cls.fieldnames, cls.fieldtypes, strict=True)
    ]


_encode_str: Callable[[str], str] = json.encoder.encode_basestring


def _json_text(value: Any) -> str:
    """A char field as `view` and `dumps` write it (a JSON string)."""
    if isinstance(value, bytes):  # pymavlink's format_attr
        value = value.decode(errors="backslashreplace").rstrip("\x00")
    return _encode_str(value) if isinstance(value, str) else _JSON.encode(value)


def _json_floats(values: Any) -> str:
    return "[" + ",".join(map(repr, values)) + "]"


def _json_writer(dialect: str, msgid: int) -> Callable[[Any], bytes]:
    """A function giving ``dumps(payload)`` of `MavlinkDecoder.view`'s payload of a message
    of this type, byte for byte, without building the dict: one ``%`` template of the whole
    object, filled from one `attrgetter` call. A float is written by ``repr``, as `json`
    writes it, an integer by ``str``; when any float is not finite (their sum is not), each
    field is written or left out on its own (`NULL_RULE`)."""
    return _json_writers(dialect, msgid)[0]


def _json_values_writer(
    dialect: str, msgid: int
) -> Callable[[int, int, int, tuple[Any, ...]], bytes]:
    """`_json_writer`'s function taking the header's ``(sysid, compid, seq)`` and the fields'
    values in declaration order instead of a message (`MavlinkDecoder.decode_json`)."""
    return _json_writers(dialect, msgid)[1]


@cache
def _json_writers(dialect: str, msgid: int) -> tuple[Callable[..., bytes], Callable[..., bytes]]:
    """`_json_writer` and `_json_values_writer`: one body, generated source as pymavlink's
    own; it names only local variables (``v0``, ``v1`` …) and helpers; field names reach it
    as data, never as code."""
    cls = dialect_module(dialect).mavlink_map[msgid]
    fields = _fields(cls)
    keys = ["," + _encode_str(name) + ":" for name, _, _ in fields]
    head = '{"header":{"sysid":%s,"compid":%s,"seq":%s}'
    template = [head]
    values = []  # what fills each field's place in the template
    finite = []  # terms whose sum is finite only when every float is finite
    each = []  # the field-by-field path, when some float is not
    for i, (_, ftype, length) in enumerate(fields):
        v = f"v{i}"
        if ftype in _FLOAT_TYPES and not length:
            template.append(keys[i].replace("%", "%%") + "%r")
            values.append(v)
            finite.append(v)
            each.append(f"    if fin({v}): out.append(K[{i}] + repr({v}))")
        elif ftype in _FLOAT_TYPES:
            template.append(keys[i].replace("%", "%%") + "%s")
            values.append(f"floats({v})")
            finite.append(f"sum({v})")
            each.append(f"    if all(map(fin, {v})): out.append(K[{i}] + floats({v}))")
        else:
            one_int = ftype in _INT_TYPES and not length
            template.append(keys[i].replace("%", "%%") + "%s")
            values.append(v if one_int else f"text({v})")
            each.append(f"    out.append(K[{i}] + str({values[-1]}))")
    header = "sysid, compid, seq"
    whole = f"(T % ({', '.join([header, *values])},)).encode()"
    body = []
    if finite:
        body.append(f"    if fin({' + '.join(finite)}):")
        body.append(f"        return {whole}")
        body.append(f"    out = [H % ({header})]")
        body.extend(each)
        body.append('    return ("".join(out) + "}").encode()')
    else:
        body.append(f"    return {whole}")
    names = ", ".join(f"v{i}" for i in range(len(fields)))
    lines = [
        "def write(m):",
        "    sysid, compid, seq = m.get_srcSystem(), m.get_srcComponent(), m.get_seq()",
    ]
    if len(fields) == 1:
        lines.append("    v0 = get(m)")
    elif fields:
        lines.append(f"    {names} = get(m)")
    lines += [*body, "def write_values(sysid, compid, seq, values):"]
    if fields:
        lines.append(f"    {names}, = values")
    lines += body
    space: dict[str, Any] = {
        "T": "".join(template) + "}",
        "H": head,
        "K": keys,
        "get": attrgetter(*(name for name, _, _ in fields)) if fields else None,
        "fin": math.isfinite,
        "floats": _json_floats,
        "text": _json_text,
    }
    exec("\n".join(lines), space)
    return space["write"], space["write_values"]


_STX_V2 = 0xFD
_UNSURE = object()  # `MavlinkDecoder._fast_json`: pymavlink must decide


@dataclass(frozen=True, slots=True)
class _Plan:
    """How `MavlinkDecoder.decode_json` makes the JSON view of one message type's frames."""

    name: str
    layout: Any  # uavtool.mavlink.payload.Layout: where pymavlink's decode finds each field
    values: Callable[[Any, bytes], tuple[Any, ...]]  # uavtool.mavlink.payload.values
    crc: Callable[[bytes], int]  # the dialect's frame CRC
    write: Callable[[int, int, int, tuple[Any, ...]], bytes]


def _plan(dialect: str, msgid: int) -> _Plan | None:
    """The `_Plan` of a message type, or None for one with a char field: pymavlink's message
    turns those into text its own way (which has changed between its versions)."""
    from uavtool.mavlink.payload import frame_crc, layout, values  # noqa: PLC0415

    module = dialect_module(dialect)
    cls = module.mavlink_map[msgid]
    lay = layout(cls)
    if lay.has_text:
        return None
    return _Plan(cls.msgname, lay, values, frame_crc(module), _json_values_writer(dialect, msgid))


class MavlinkDecoder:
    """Decodes whole MAVLink frames of one dialect into JSON-ready dicts (not thread-safe)."""

    def __init__(self, dialect: str = DEFAULT_DIALECT) -> None:
        self.dialect = dialect
        module = dialect_module(dialect)
        self._module = module
        self._known = module.mavlink_map
        self._mav = module.MAVLink(None)
        self._error = module.MAVError
        self._plans: dict[int, _Plan | None] = {}  # None: pymavlink decodes the type

    def decode(self, frame: bytes) -> tuple[int, str, dict[str, Any]] | None:
        """``(msgid, MSGNAME, payload)`` of a frame, or None if it is unknown or corrupt."""
        try:
            msg = self._mav.decode(bytearray(frame))
        except (self._error, IndexError, ValueError):
            return None
        return self.view(msg)

    def owns(self, msg: Any) -> bool:
        """Whether ``msg`` is a message of this decoder's dialect (its class, not another
        dialect's class of the same id)."""
        return type(msg) is self._known.get(msg.get_msgId())

    def view(self, msg: Any) -> tuple[int, str, dict[str, Any]] | None:
        """``(msgid, MSGNAME, payload)`` of a message this dialect decoded (from a frame's
        bytes: a message built in Python, not yet packed, has no float32 rounding), or None
        if its id is not in the dialect."""
        msgid = msg.get_msgId()
        if msgid not in self._known:
            return None
        payload: dict[str, Any] = {
            "header": {
                "sysid": msg.get_srcSystem(),
                "compid": msg.get_srcComponent(),
                "seq": msg.get_seq(),
            }
        }
        for name, kind in _view_fields(self.dialect, msgid):
            value = getattr(msg, name)
            if kind == _PLAIN:
                if isinstance(value, bytes):  # a char field: text (pymavlink's format_attr)
                    value = value.decode(errors="backslashreplace").rstrip("\x00")
            elif kind == _FLOAT:
                if not math.isfinite(value):
                    continue
            elif not all(math.isfinite(v) for v in value):
                continue
            else:
                value = list(value)
            payload[name] = value
        return msgid, msg.get_type(), payload

    def decode_json(self, frame: bytes) -> tuple[int, str, bytes] | None:
        """``(msgid, MSGNAME, JSON)`` of a frame (`decode`'s payload as `dumps` writes it),
        or None if it is unknown or corrupt."""
        fast = self._fast_json(frame)
        if fast is not _UNSURE:
            return cast("tuple[int, str, bytes] | None", fast)
        try:
            msg = self._mav.decode(bytearray(frame))
        except (self._error, IndexError, ValueError):
            return None
        return self.json(msg)

    def _fast_json(self, frame: bytes) -> object:
        """`decode_json` of an unsigned MAVLink 2 frame of a message of numbers: the very
        bytes pymavlink's decoding leads to, without building its message (its ``decode`` is
        most of the cost, and a writer process decodes every frame of a flight again);
        `_UNSURE` for any other frame (signed, MAVLink 1, a length that does not add up, an
        unknown id, a message with text, CRC checks turned off), which pymavlink then
        decodes. The CRC is checked as pymavlink checks it: None when it fails."""
        n = len(frame)
        if n < 12 or frame[0] != _STX_V2 or frame[2] or frame[1] != n - 12:
            return _UNSURE
        msgid = frame[7] | frame[8] << 8 | frame[9] << 16
        try:
            plan = self._plans[msgid]
        except KeyError:
            known = msgid in self._known
            plan = self._plans[msgid] = _plan(self.dialect, msgid) if known else None
        if plan is None:
            return _UNSURE
        lay = plan.layout
        if frame[-2] | frame[-1] << 8 != plan.crc(frame[1:-2] + lay.crc_extra):
            return _UNSURE if self._module.MAVLINK_IGNORE_CRC else None
        values = plan.values(lay, frame[10:-2])
        return msgid, plan.name, plan.write(frame[5], frame[6], frame[4], values)

    def json(self, msg: Any) -> tuple[int, str, bytes] | None:
        """``(msgid, MSGNAME, JSON)``: `view`'s payload as `dumps` writes it, byte for byte,
        made without building it (half the time), or None if the id is not in the
        dialect."""
        msgid = msg.get_msgId()
        if msgid not in self._known:
            return None
        return msgid, msg.get_type(), _json_writer(self.dialect, msgid)(msg)
