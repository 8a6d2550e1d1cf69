"""Messages of MAVLink's common.xml that the XML bundled with pymavlink lacks, and that PX4
speaks: EVENT and CURRENT_EVENT_SEQUENCE (PX4 gives its refusal reasons and most of its news
as events) and COMPONENT_METADATA (where a component's events metadata is). Registered into
the dialect uavtool speaks, so frames of these ids are decoded, and recorded with their JSON
views, like any other message. The layouts and CRC extras are common.xml's; the classes are
built the way pymavlink's generator builds its own (fields on the wire largest type first)."""

from __future__ import annotations

import struct
from types import ModuleType
from typing import Any

_TYPES = {  # C type -> (struct code, size)
    "uint8_t": ("B", 1), "int8_t": ("b", 1), "uint16_t": ("H", 2), "int16_t": ("h", 2),
    "uint32_t": ("I", 4), "int32_t": ("i", 4), "float": ("f", 4), "char": ("s", 1),
}  # fmt: skip

Field = tuple[str, str, int]
"""(name, C type, array length; 0 for a scalar), in common.xml's order."""

MESSAGES: tuple[tuple[int, str, int, tuple[Field, ...]], ...] = (
    (397, "COMPONENT_METADATA", 182,
     (("time_boot_ms", "uint32_t", 0), ("file_crc", "uint32_t", 0), ("uri", "char", 100))),
    (410, "EVENT", 160,
     (("destination_component", "uint8_t", 0), ("destination_system", "uint8_t", 0),
      ("id", "uint32_t", 0), ("event_time_boot_ms", "uint32_t", 0), ("sequence", "uint16_t", 0),
      ("log_levels", "uint8_t", 0), ("arguments", "uint8_t", 40))),
    (411, "CURRENT_EVENT_SEQUENCE", 106, (("sequence", "uint16_t", 0), ("flags", "uint8_t", 0))),
)  # fmt: skip
"""(id, name, CRC extra, fields) of each message added."""


def register(mavlink: ModuleType) -> None:
    """Add the messages to a pymavlink dialect module (idempotent)."""
    for msgid, name, crc_extra, fields in MESSAGES:
        if msgid not in mavlink.mavlink_map:
            cls = _message_class(mavlink.MAVLink_message, msgid, name, crc_extra, fields)
            mavlink.mavlink_map[msgid] = cls
            setattr(mavlink, cls.__name__, cls)
            setattr(mavlink, f"MAVLINK_MSG_ID_{name}", msgid)


def _message_class(
    base: type, msgid: int, name: str, crc_extra: int, fields: tuple[Field, ...]
) -> type:
    wire = sorted(fields, key=lambda f: -_TYPES[f[1]][1])  # stable: largest type first
    fmt = "<" + "".join(
        f"{n}s" if t == "char" and n else f"{n}{_TYPES[t][0]}" if n else _TYPES[t][0]
        for _, t, n in wire
    )
    names = [f[0] for f in fields]
    wire_names = [f[0] for f in wire]

    def __init__(self: Any, *values: Any) -> None:  # noqa: N807 - pymavlink's shape
        base.__init__(self, msgid, name)  # type: ignore[misc]
        self._fieldnames = names
        self._instance_field = None
        self._instance_offset = -1
        for field, value in zip(names, values, strict=True):
            setattr(self, field, value)

    def pack(self: Any, mav: Any, force_mavlink1: bool = False) -> Any:
        values: list[Any] = []
        for field, ftype, n in wire:
            value = getattr(self, field)
            values.extend(value if n and ftype != "char" else [value])
        payload = struct.pack(fmt, *values)
        return self._pack(mav, crc_extra, payload, force_mavlink1=force_mavlink1)

    return type(
        f"MAVLink_{name.lower()}_message",
        (base,),
        {
            "__init__": __init__,
            "pack": pack,
            "id": msgid,
            "msgname": name,
            "fieldnames": names,
            "ordered_fieldnames": wire_names,
            "fieldtypes": [f[1] for f in fields],
            "fielddisplays_by_name": {},
            "fieldenums_by_name": {},
            "fieldunits_by_name": {},
            "orders": [wire_names.index(n) for n in names],
            "lengths": [1 if t == "char" or not n else n for _, t, n in wire],
            "array_lengths": [f[2] for f in wire],
            "crc_extra": crc_extra,
            "unpacker": struct.Struct(fmt),
            "instance_field": None,
            "instance_offset": -1,
        },
    )
