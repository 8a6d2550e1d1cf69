"""`uavtool fly --rerun FILE.rrd`: the flight streamed live through the same logger as
`uavtool view`, so the live file holds the same kinds of entities."""

from __future__ import annotations

import time
from pathlib import Path

from click.testing import CliRunner

from tests.view.rrd import read_rrd
from uavtool.cli import cli


def test_fly_rerun_streams_the_same_entities_as_view(tmp_path: Path) -> None:
    live = tmp_path / "live.rrd"
    started = time.monotonic()
    result = CliRunner().invoke(cli, ["fly", "-q", "--no-record", "--rerun", str(live)])
    assert result.exit_code == 0, result.output
    # A file is no live viewer: the flight runs at full speed (224 s of flight at real-time
    # pace would take minutes).
    assert time.monotonic() - started < 60.0
    data, blueprint = read_rrd(live)
    entities = data.entities()
    for entity in ("world/scene/ground", "world/vehicle", "world/camera/image", "world/model"):
        assert any(e == entity or e.startswith(entity + "/") for e in entities), entity
    frames = [r for r in data.rows["world/camera/image"] if any("EncodedImage" in k for k in r)]
    assert len(frames) == 7  # 2 overviews, red (the only one of the target's hue), top, front,
    # right, diagonal
    assert blueprint.entities()  # the default layout travels with the stream


def test_a_rerun_target_that_is_no_viewer_nor_rrd_file_is_refused(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["fly", "--no-record", "--rerun", "nosuch"])
    assert result.exit_code == 2
    assert "expected spawn, web or a file ending in .rrd" in result.output
    assert not Path("nosuch").exists()
