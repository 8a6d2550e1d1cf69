"""Every golden recording replays bit for bit (through the uavtool pytest plugin)."""

from __future__ import annotations

from pathlib import Path

from uavtool.replay.golden import digest_path, recorded_digest
from uavtool.testing import assert_reflies_identically, assert_replays_identically


def test_golden_replays_identically(uavtool_recording: Path) -> None:
    assert_replays_identically(uavtool_recording)


def test_golden_reflies_identically(uavtool_recording: Path) -> None:
    """Flown again from its metadata, each golden gives the same recording: the vehicle, the
    link, the renderer and the mission together."""
    assert_reflies_identically(uavtool_recording)


def test_golden_digest_is_current(uavtool_recording: Path) -> None:
    """The reviewable digest beside each golden matches its recorded outputs."""
    expected = digest_path(uavtool_recording).read_text()
    assert recorded_digest(uavtool_recording) == expected
