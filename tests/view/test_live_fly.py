"""`uavtool fly --rerun FILE.rrd`: the flight streamed live through the same logger as
`uavtool view`, so the live file holds the same kinds of entities."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from tests.view.rrd import read_rrd
from uavtool.cli import cli


def test_fly_rerun_streams_the_same_entities_as_view(tmp_path: Path) -> None:
    live = tmp_path / "live.rrd"
    result = CliRunner().invoke(
        cli, ["fly", "-q", "--no-record", "--speedup", "max", "--rerun", str(live)]
    )
    assert result.exit_code == 0, result.output
    data, blueprint = read_rrd(live)
    entities = data.entities()
    for entity in ("world/scene/ground", "world/vehicle", "world/camera/image", "world/model"):
        assert any(e == entity or e.startswith(entity + "/") for e in entities), entity
    frames = [r for r in data.rows["world/camera/image"] if any("EncodedImage" in k for k in r)]
    assert len(frames) == 10  # 2 overviews, 4 points of interest, top, front, right, diagonal
    assert blueprint.entities()  # the default layout travels with the stream
