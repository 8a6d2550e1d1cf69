"""PX4's events in words: libevents metadata fetched from the vehicle over MAVLink FTP (the
URI its COMPONENT_METADATA names), cached by CRC, and EVENT messages decoded with it."""

from __future__ import annotations

import json
import random
import struct
from pathlib import Path
from typing import Any

import pytest

from tests.autopilot.fake_px4 import FakePX4, link_to, xz
from uavtool.autopilot.px4 import PX4
from uavtool.autopilot.px4_events import EventDecoder, fetch_decoder
from uavtool.errors import LinkError
from uavtool.link.ftp import read_file
from uavtool.mavlink.dialect import mavlink as M

METADATA: dict[str, Any] = {
    "version": 2,
    "components": {
        "1": {
            "namespace": "px4",
            "enums": {
                "modes_t": {"type": "uint32_t", "is_bitfield": True, "entries": {
                    "1": {"name": "manual", "description": "Manual"},
                    "4": {"name": "posctl", "description": "Position"},
                }},
                "action_t": {"type": "uint8_t", "entries": {"2": {"name": "rtl",
                                                                   "description": "Return"}}},
            },
            "event_groups": {"default": {"events": {
                "1234": {"name": "wind", "message": "Wind {1:.1m/s} above {2m_v}",
                         "arguments": [{"name": "a", "type": "float"},
                                       {"name": "b", "type": "uint16_t"}]},
                "77": {"name": "denied", "message": "Arming denied: {2} in <param>X</param>",
                       "arguments": [{"name": "m", "type": "px4::modes_t"},
                                     {"name": "act", "type": "action_t"}]},
                "78": {"name": "modes", "message": "Not allowed in {1}",
                       "arguments": [{"name": "m", "type": "modes_t"}]},
            }}},
        },
    },
}  # fmt: skip


def _event(component: int, sub_id: int, arguments: bytes, level: int = 4) -> Any:
    args = list(arguments.ljust(40, b"\0"))
    return M.MAVLink_event_message(0, 0, (component << 24) | sub_id, 10, 1, level, args)


def test_events_read_as_their_messages_with_arguments_units_and_enums() -> None:
    decoder = EventDecoder(METADATA)
    wind = _event(1, 1234, struct.pack("<fH", 12.345, 40))
    assert decoder.describe(wind) == (4, "Wind 12.3 m/s above 40 m")
    denied = _event(1, 77, struct.pack("<IB", 5, 2), level=3)
    assert decoder.describe(denied) == (3, "Arming denied: Return in X")  # tags stripped
    assert (
        decoder.describe(_event(1, 78, struct.pack("<I", 5)))[1]
        == "Not allowed in Manual, Position"
    )
    assert decoder.describe(_event(1, 999, b""))[1] == "event 1:999"  # unknown: its number


def test_the_metadata_comes_over_mavlink_ftp_and_is_cached(tmp_path: Path) -> None:
    noise = random.Random(7).randbytes(3000).hex()  # ~3 kB of xz: a dozen FTP reads
    events = json.dumps({**METADATA, "noise": noise}).encode()
    general = {"version": 1, "metadataTypes": [
        {"type": 4, "fileCrc": 0xABC, "uri": "mftp://etc/extras/all_events.json.xz"}]}  # fmt: skip
    files = {
        "/etc/extras/component_general.json.xz": xz(json.dumps(general).encode()),
        "/etc/extras/all_events.json.xz": xz(events),
    }
    fake = FakePX4(files, drop_first=3)  # answers lost on the link: asked again
    decoder = fetch_decoder(link_to(fake), cache_dir=tmp_path)
    assert len(decoder) == 3
    assert (tmp_path / "events-00000abc.json").is_file()
    again = FakePX4({"/etc/extras/component_general.json.xz": files[
        "/etc/extras/component_general.json.xz"]})  # fmt: skip
    assert len(fetch_decoder(link_to(again), cache_dir=tmp_path)) == 3  # from the cache
    opened = [bytes(m.payload[12 : 12 + m.payload[4]]) for m in again.sent
              if m.get_type() == "FILE_TRANSFER_PROTOCOL" and m.payload[3] == 4]  # fmt: skip
    assert opened == [b"/etc/extras/component_general.json.xz"]  # not the events again


def test_a_vehicle_without_the_file_is_a_link_error_and_events_read_as_numbers() -> None:
    link = link_to(FakePX4({}))
    with pytest.raises(LinkError, match="refused"):
        read_file(link, "/etc/nothing")
    px4 = PX4()
    assert "numbers" in px4.prepare(link)
    said = px4.vehicle_text(_event(1, 1234, b"", level=3))
    assert said == (3, f"event {(1 << 24) | 1234}")
    assert px4.vehicle_text(_event(1, 1234, b"", level=8)) is None  # protocol level: not news


def test_px4_saying_a_thing_twice_is_said_once_and_standing_reports_are_not_warnings() -> None:
    metadata = json.loads(json.dumps(METADATA))
    group = metadata["components"]["1"]["event_groups"]
    group["health"] = {"events": {"55": {"name": "no_rc", "message": "No manual control input"}}}
    px4 = PX4(EventDecoder(metadata))
    low = M.MAVLink_statustext_message(M.MAV_SEVERITY_WARNING, b"Arming denied: X\t")
    denied = _event(1, 77, struct.pack("<IB", 0, 2), level=4)
    assert px4.vehicle_text(low) == (4, "Arming denied: X")
    assert px4.vehicle_text(_event(1, 77, b"", level=4)) is not None  # another text
    assert px4.vehicle_text(low) == (4, "Arming denied: X")
    again = M.MAVLink_statustext_message(M.MAV_SEVERITY_WARNING, b"Arming denied: Return in X")
    assert px4.vehicle_text(denied) == (4, "Arming denied: Return in X")
    assert px4.vehicle_text(again) is None  # the same words, the other way, right after
    assert px4.vehicle_text(again) == (4, "Arming denied: Return in X")  # said again: news
    severity, text = px4.vehicle_text(_event(1, 55, b"", level=3)) or (0, "")
    assert (severity, text) == (M.MAV_SEVERITY_INFO, "No manual control input")
