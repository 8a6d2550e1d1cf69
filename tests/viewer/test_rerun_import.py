"""Rerun's own MCAP importer (``rerun FILE.mcap``, here its converter ``rerun mcap convert``
from the installed rerun-sdk) turns every golden recording into Rerun archetypes: the photos,
the camera's calibration and pose, the vehicle's fix and pose, the mission's log. The rest
(MAVLink JSON channels, raw frames, SceneUpdates) it keeps as plain messages."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from mcap.reader import make_reader

from uavtool.recording.fleet import split_topic

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))

# topic -> the archetype Rerun's importer makes of its Foxglove schema
ARCHETYPES = {
    "/camera/image": "EncodedImage",
    "/mission/target": "EncodedImage",
    "/camera/calibration": "Pinhole",
    "/camera/pose": "Transform3D",
    "/vehicle/fix": "GeoPoints",
    "/vehicle/pose": "InstancePoses3D",
    "/mission/events": "TextLog",
}


def _rerun() -> str:
    found = shutil.which("rerun")
    if found is None:
        pytest.fail("the rerun command of rerun-sdk is not on PATH")
    return found


@pytest.mark.parametrize("recording", GOLDEN, ids=[p.stem for p in GOLDEN])
def test_rerun_imports_the_foxglove_channels_as_archetypes(recording: Path, tmp_path: Path) -> None:
    env = dict(os.environ, RERUN_ANALYTICS="0")  # no network, no first-run banner
    rrd = tmp_path / "imported.rrd"
    subprocess.run(
        [_rerun(), "mcap", "convert", str(recording), "-o", str(rrd)],
        check=True,
        capture_output=True,
        env=env,
        timeout=120,
    )
    # Rerun's own check of what it wrote: every column deserializes (before LocationFix had a
    # colour, 229 errors on /vehicle/fix:GeoPoints:colors in the paper golden)
    verified = subprocess.run(
        [_rerun(), "rrd", "verify", str(rrd)],
        check=False,
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert verified.returncode == 0, verified.stderr[-2000:]
    printed = subprocess.run(
        [_rerun(), "rrd", "print", "-v", str(rrd)],
        check=True,
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    ).stdout
    # "Chunk(…) with 10 rows (3.7 KiB) - /vehicle/pose - data columns: [/vehicle/pose@…"
    rows: dict[tuple[str, str], int] = {}
    pattern = r" with (\d+) rows \([^)]*\) - (/\S+) - data columns: \[([^\]]*)\]"
    for n, topic, columns in re.findall(pattern, printed):
        for archetype in set(re.findall(r"@(\w+):", columns)):
            rows[(topic, archetype)] = rows.get((topic, archetype), 0) + int(n)
    counts = _message_counts(recording)
    for topic, archetype in ARCHETYPES.items():
        # one row per message: every photo, pose, fix and log line is there, each vehicle's
        # of a fleet (/uavK/camera/image …) on its own entity
        written = [t for t in counts if t == topic or split_topic(t)[1] == topic]
        assert written, (topic, sorted(counts))
        for each in written:
            assert rows.get((each, archetype)) == counts[each], (each, archetype, rows)


def _message_counts(recording: Path) -> dict[str, int]:
    with recording.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    return {
        summary.channels[cid].topic: n
        for cid, n in summary.statistics.channel_message_counts.items()
    }
