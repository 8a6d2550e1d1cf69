"""PX4's events, in words: the EVENT message carries an id and packed arguments; the text is
in the component's events metadata (libevents' JSON, ``all_events.json.xz``), which PX4
serves over MAVLink FTP at the URI its COMPONENT_METADATA names — how QGroundControl gets it.
Fetched once per metadata version (its CRC) into the user's cache."""

from __future__ import annotations

import json
import lzma
import math
import os
import re
import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

from uavtool.errors import LinkError
from uavtool.link import VehicleLink
from uavtool.link.ftp import read_file
from uavtool.mavlink.dialect import mavlink as M

EVENTS_METADATA = 4
"""COMP_METADATA_TYPE_EVENTS: its entry in the general metadata."""
_SCALARS = {
    "uint8_t": "<B", "int8_t": "<b", "uint16_t": "<H", "int16_t": "<h", "uint32_t": "<I",
    "int32_t": "<i", "uint64_t": "<Q", "int64_t": "<q", "float": "<f",
}  # fmt: skip
_PLACEHOLDER = re.compile(r"\{(\d+)(?::\.(\d+))?([^}]*)\}")
_TAG = re.compile(r"</?[a-z]+[^>]*>")
_UNITS = {"m_v": "m", "m/s_v": "m/s"}  # libevents' "vertical" variants read as plain units


class EventDecoder:
    """Texts for EVENT messages from libevents metadata (the parsed ``all_events.json``)."""

    def __init__(self, metadata: dict[str, Any]) -> None:
        self._events: dict[int, tuple[str, list[str], str, str]] = {}
        self._enums: dict[str, dict[str, Any]] = {}  # "namespace::name" -> enum
        components = metadata.get("components", {})
        for component_id, component in components.items():
            namespace = str(component.get("namespace", ""))
            for name, enum in component.get("enums", {}).items():
                self._enums[f"{namespace}::{name}"] = enum
            for group_name, group in component.get("event_groups", {}).items():
                for sub_id, event in group.get("events", {}).items():
                    event_id = (int(component_id) << 24) | int(sub_id)
                    types = [str(a.get("type", "")) for a in event.get("arguments", [])]
                    message = str(event.get("message", ""))
                    self._events[event_id] = (message, types, namespace, str(group_name))

    def __len__(self) -> int:
        return len(self._events)

    def describe(self, msg: Any) -> tuple[int, str]:
        """(MAV_SEVERITY, text) of an EVENT; an unknown id reads as its number."""
        severity = int(msg.log_levels) & 0x0F  # external level: Emergency 0 … Debug 7
        known = self._events.get(int(msg.id))
        if known is None:
            return severity, f"event {int(msg.id) >> 24}:{int(msg.id) & 0xFFFFFF}"
        template, types, namespace, _ = known
        values = self._arguments(bytes(msg.arguments), types, namespace)
        return severity, self._text(template, values, types, namespace)

    def group(self, msg: Any) -> str:
        """The event's group in the metadata ("" if unknown): ``health`` and ``arming_check``
        events are PX4's standing reports of what each mode lacks, not news."""
        known = self._events.get(int(msg.id))
        return known[3] if known is not None else ""

    def _enum(self, ftype: str, namespace: str) -> dict[str, Any] | None:
        name = ftype if "::" in ftype else f"{namespace}::{ftype}"
        bare = ftype.rsplit("::", maxsplit=1)[-1]
        return self._enums.get(name) or self._enums.get(f"common::{bare}")

    def _arguments(self, raw: bytes, types: list[str], namespace: str) -> list[float | int]:
        values: list[float | int] = []
        offset = 0
        for ftype in types:
            enum = self._enum(ftype, namespace)
            code = _SCALARS.get(str(enum.get("type")) if enum else ftype)
            if code is None or offset + struct.calcsize(code) > len(raw):
                break
            values.append(struct.unpack_from(code, raw, offset)[0])
            offset += struct.calcsize(code)
        return values

    def _text(
        self, template: str, values: list[float | int], types: list[str], namespace: str
    ) -> str:
        def one(match: re.Match[str]) -> str:
            index = int(match.group(1)) - 1
            if index >= len(values):
                return match.group(0)
            value, unit = values[index], _UNITS.get(match.group(3), match.group(3))
            enum = self._enum(types[index], namespace)
            if enum is not None:
                return _enum_text(enum, int(value))
            if isinstance(value, float):
                digits = match.group(2)
                text = f"{value:.{digits}f}" if digits and math.isfinite(value) else f"{value:g}"
            else:
                text = str(value)
            return f"{text} {unit}" if unit else text

        text = _PLACEHOLDER.sub(one, template)
        return _TAG.sub("", text).replace("\\<", "<").replace("\\>", ">").replace("\\{", "{")


def _enum_text(enum: dict[str, Any], value: int) -> str:
    entries = enum.get("entries", {})
    if enum.get("is_bitfield"):
        names = [
            str(e.get("description") or e.get("name"))
            for bit, e in entries.items()
            if int(bit) and value & int(bit) == int(bit)
        ]
        return ", ".join(names) or str(value)
    entry = entries.get(str(value))
    return str(entry.get("description") or entry.get("name")) if entry else str(value)


def fetch_decoder(
    link: VehicleLink,
    *,
    cache_dir: Path | None = None,
    on_wait: Callable[[], None] | None = None,
) -> EventDecoder:
    """The vehicle's events metadata, from the cache when its CRC is there, else over
    MAVLink FTP; LinkError when the vehicle names none or does not serve it."""
    general = _general_metadata(link, on_wait)
    entry = next(
        (m for m in general.get("metadataTypes", []) if m.get("type") == EVENTS_METADATA), None
    )
    if entry is None or not str(entry.get("uri", "")).startswith("mftp://"):
        raise LinkError(f"{link.name}: the vehicle's metadata names no events file it serves")
    cache = (cache_dir or _cache_dir()) / f"events-{int(entry.get('fileCrc', 0)):08x}.json"
    if cache.is_file():
        try:
            return EventDecoder(json.loads(cache.read_text()))
        except (OSError, ValueError):
            pass  # a damaged cache entry: fetch it again
    data = _unpack(read_file(link, _ftp_path(entry["uri"]), on_wait=on_wait), entry["uri"])
    metadata = json.loads(data)
    try:
        cache.parent.mkdir(parents=True, exist_ok=True)
        tmp = cache.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_bytes(data)
        tmp.replace(cache)
    except OSError:
        pass  # no cache: fetched again next time
    return EventDecoder(metadata)


def _general_metadata(link: VehicleLink, on_wait: Callable[[], None] | None) -> dict[str, Any]:
    """The component's general metadata (JSON), whose URI COMPONENT_METADATA gives."""
    uri = ""
    deadline = link.clock() + 3.0
    asked = -math.inf
    while not uri and link.clock() < deadline:
        if link.clock() - asked > 0.5:
            link.command_long(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_COMPONENT_METADATA)
            asked = link.clock()
        for msg in link.poll(0.05):
            if msg.get_type() == "COMPONENT_METADATA":
                uri = _text(msg.uri)
        if on_wait is not None:
            on_wait()
    if not uri.startswith("mftp://"):
        raise LinkError(f"{link.name}: no COMPONENT_METADATA with a MAVLink FTP URI")
    data = _unpack(read_file(link, _ftp_path(uri), on_wait=on_wait), uri)
    general = json.loads(data)
    if not isinstance(general, dict):
        raise LinkError(f"{link.name}: {uri}: not a metadata object")
    return general


def _ftp_path(uri: str) -> str:
    """``mftp://[;comp=1]etc/extras/x.json.xz`` -> ``/etc/extras/x.json.xz``."""
    path = uri.removeprefix("mftp://")
    if path.startswith("[;"):
        path = path[path.index("]") + 1 :]
    return "/" + path.lstrip("/")


def _unpack(data: bytes, uri: str) -> bytes:
    if uri.endswith(".xz"):
        try:
            return lzma.decompress(data)
        except lzma.LZMAError as exc:
            raise LinkError(f"{uri}: not xz: {exc}") from None
    return data


def _text(value: Any) -> str:
    raw = value if isinstance(value, bytes) else str(value).encode()
    return raw.split(b"\0", 1)[0].decode(errors="replace")


def _cache_dir() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(root) / "uavtool" / "px4-events"
