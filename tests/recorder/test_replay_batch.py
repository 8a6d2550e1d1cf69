"""`uavtool replay DIR --vision-only --target PNG` on a 1-worker Dask cluster: a recording of
`uavtool record` gets the per-photo vision of the single-file path, one row with the photos
matched, beside a mission recording replayed as before."""

from __future__ import annotations

import logging
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.recorder.flight import STOPS, Recorded
from uavtool.camera import Intrinsics
from uavtool.cli import cli
from uavtool.recording import JsonDocument, RecordingReader
from uavtool.recording.topics import FRAMES
from uavtool.runner.fly import target_picture
from uavtool.sweep.table import read_table
from uavtool.world import load_scene

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden" / "paper.mcap"


@pytest.fixture(scope="module")
def scheduler() -> Iterator[str]:
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=logging.ERROR,
    ) as cluster:
        yield str(cluster.scheduler_address)


@pytest.fixture
def folder(recorded: Recorded, tmp_path: Path) -> Path:
    flights = tmp_path / "flights"
    flights.mkdir()
    shutil.copy(recorded.path, flights / "recorded.mcap")
    shutil.copy(GOLDEN, flights / "mission.mcap")
    return flights


def _red_photo_frame(path: Path) -> int:
    red = list(STOPS).index("red")
    with RecordingReader(path) as reader:
        for entry in reader.entries([FRAMES]):
            assert isinstance(entry.value, JsonDocument)
            if entry.value.payload["photo"] == red:
                return int(entry.value.payload["frame_index"])
    raise AssertionError("no photo of the red building")


def test_vision_only_matches_the_photos_of_a_record_file_on_dask(
    folder: Path, tmp_path: Path, scheduler: str
) -> None:
    target = tmp_path / "red.png"
    target.write_bytes(target_picture(load_scene("paper"), Intrinsics.from_hfov()))
    table = tmp_path / "photos.csv"
    args = ["replay", "--vision-only", str(folder), "--target", str(target)]
    result = CliRunner().invoke(cli, [*args, "--output", str(table), "--scheduler", scheduler])
    assert result.exit_code == 0, result.output
    rows = {Path(r["recording"]).name: r for r in read_table(table)}
    rec = rows["recorded.mcap"]
    assert rec["result"] == "vision-only" and not rec["error"]
    assert (rec["photos"], rec["photos_matched"]) == (len(STOPS), 1)
    assert str(rec["matched_frames"]) == str(_red_photo_frame(folder / "recorded.mcap"))
    assert rec["decision_after_from"] == "photos"
    mission = rows["mission.mcap"]  # the mission recording: its own target, as before
    assert mission["result"] == "vision-only" and mission["matched_poi_after"] == 3
    assert mission["photos"] is None
    assert "photos         1 of 4 match the target, in 1 recording of uavtool record" in (
        result.output
    )


def test_a_record_file_without_target_is_an_error_row_that_says_what_to_give(
    folder: Path, tmp_path: Path, scheduler: str
) -> None:
    (folder / "mission.mcap").unlink()
    table = tmp_path / "photos.parquet"
    args = ["replay", "--vision-only", str(folder), "--output", str(table)]
    result = CliRunner().invoke(cli, [*args, "--scheduler", scheduler])
    assert result.exit_code == 0, result.output
    [row] = read_table(table)
    assert row["result"] == "error" and "give one with --target PNG" in row["error"]
    assert "give one with --target PNG" in result.output


def test_target_without_vision_only_is_a_usage_error(folder: Path) -> None:
    target = str(folder / "recorded.mcap")  # any file: refused before it is read
    result = CliRunner().invoke(cli, ["replay", str(folder), "--target", target])
    assert result.exit_code == 2
    assert "--target is for --vision-only" in result.output


def test_vision_runs_on_the_photos_of_a_record_file(recorded: Recorded, tmp_path: Path) -> None:
    """``replay --vision`` takes a recording of ``uavtool record`` as one of ``uavtool fly``."""
    out = tmp_path / "detected.mcap"
    result = CliRunner().invoke(
        cli,
        ["replay", str(recorded.path), "--vision", "tests.plugins.detector:red_roofs",
         "--output", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    with RecordingReader(out) as reader:
        found = [e.value.payload for e in reader.entries(["/vision/detections"])]
        frames = [e.value.payload for e in reader.entries([FRAMES])]
    assert [f["frame_index"] for f in found] == [f["frame_index"] for f in frames]
    drawn = sum(len(f["detections"]) for f in found)
    assert drawn > 0  # the red building is in some photo
    shown = CliRunner().invoke(cli, ["view", str(out), "--save", str(tmp_path / "d.rrd")])
    assert shown.exit_code == 0 and f"{drawn} detection" in shown.output, shown.output
