"""The common.xml messages uavtool adds to pymavlink's dialect (EVENT, CURRENT_EVENT_SEQUENCE,
COMPONENT_METADATA) are what pymavlink's own generator makes of their XML: same wire layout and
CRC extra, so frames from PX4 decode; and each survives a round trip through our parser."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from types import ModuleType

import pytest

from uavtool.mavlink.dialect import mavlink as M
from uavtool.mavlink.events import MESSAGES
from uavtool.mavlink.framing import FrameParser, new_encoder

_ATTRIBUTES = ("fieldnames", "ordered_fieldnames", "fieldtypes", "orders", "lengths",
               "array_lengths", "crc_extra")  # fmt: skip


def _xml() -> str:
    messages = []
    for msgid, name, _, fields in MESSAGES:
        rows = "".join(
            f'<field type="{t}{f"[{n}]" if n else ""}" name="{f}">{f}</field>' for f, t, n in fields
        )
        messages.append(
            f'<message id="{msgid}" name="{name}"><description>x</description>{rows}</message>'
        )
    return f"<mavlink><version>3</version><messages>{''.join(messages)}</messages></mavlink>"


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    """pymavlink's generator on the same definitions (as common.xml has them)."""
    folder = tmp_path_factory.mktemp("mavgen")
    xml = folder / "events.xml"
    xml.write_text(_xml())
    out = folder / "events_dialect.py"
    subprocess.run(
        [sys.executable, "-m", "pymavlink.tools.mavgen", "--lang", "Python3",
         "--wire-protocol", "2.0", "--output", str(out), str(xml)],
        check=True, capture_output=True,
    )  # fmt: skip
    spec = importlib.util.spec_from_file_location("events_dialect", out)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("name", [m[1] for m in MESSAGES])
def test_the_layout_is_pymavlinks_own(generated: ModuleType, name: str) -> None:
    ours = getattr(M, f"MAVLink_{name.lower()}_message")
    theirs = getattr(generated, f"MAVLink_{name.lower()}_message")
    for attribute in _ATTRIBUTES:
        assert getattr(ours, attribute) == getattr(theirs, attribute), attribute
    assert ours.unpacker.format == theirs.unpacker.format


def test_frames_decode_both_ways(generated: ModuleType) -> None:
    event = M.MAVLink_event_message(0, 0, (1 << 24) | 10011251, 1234, 7, 0x64, list(range(40)))
    raw = bytes(event.pack(new_encoder(sysid=1, compid=1)))
    (frame,) = FrameParser().feed(raw)
    assert (frame.msg.id, frame.msg.sequence, frame.msg.arguments[39]) == (
        (1 << 24) | 10011251,
        7,
        39,
    )
    theirs = generated.MAVLink(None).decode(bytearray(raw))
    assert theirs.id == frame.msg.id and list(theirs.arguments) == frame.msg.arguments
    meta = M.MAVLink_component_metadata_message(5, 77, b"mftp://etc/extras/x.json.xz")
    (frame,) = FrameParser().feed(bytes(meta.pack(new_encoder(sysid=1, compid=1))))
    assert frame.msg.uri in (b"mftp://etc/extras/x.json.xz", "mftp://etc/extras/x.json.xz")
