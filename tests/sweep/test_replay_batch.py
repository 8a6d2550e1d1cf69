"""``uavtool replay DIR_OR_GLOB`` on the 2-worker cluster: one row per recording."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.recording import summarize
from uavtool.sweep.table import read_table

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden"


def test_check_over_the_golden_folder_reports_all_identical(tmp_path: Path, scheduler: str) -> None:
    table = tmp_path / "check.parquet"
    result = CliRunner().invoke(
        cli, ["replay", "--check", str(GOLDEN), "--output", str(table), "--scheduler", scheduler]
    )
    assert result.exit_code == 0, result.output
    rows = read_table(table)
    assert [Path(r["recording"]).name for r in rows] == sorted(
        p.name for p in GOLDEN.glob("*.mcap")
    )
    assert {r["result"] for r in rows} == {"identical"}
    assert not any(r["decision_changed"] for r in rows)
    n = len(rows)
    assert f"decisions      0 of {n} flights change their decision" in result.output
    assert table.with_suffix(".txt").read_text().startswith(f"recordings     {n} of {n}")


def test_a_changed_parameter_reports_the_flights_that_differ(
    tmp_path: Path, scheduler: str
) -> None:
    table = tmp_path / "threshold.csv"
    pattern = str(GOLDEN / "paper*.mcap")
    outcome = summarize(GOLDEN / "paper.mcap").outcome
    assert outcome is not None
    threshold = round(float(outcome["match_score"]) + 0.001, 4)  # just above the match
    result = CliRunner().invoke(
        cli,
        [
            "replay",
            "--check",
            pattern,
            "--set",
            f"recognize.threshold={threshold}",
            "--output",
            str(table),
            "--scheduler",
            scheduler,
        ],
    )
    assert result.exit_code == 1, result.output
    rows = {Path(r["recording"]).name: r for r in read_table(table)}
    assert set(rows) == {p.name for p in GOLDEN.glob("paper*.mcap")}
    paper = rows["paper.mcap"]
    # Just above the target's score on the recorded photo, nothing matches any more.
    assert paper["result"] in {"differs", "diverged"}
    assert "Recognition" in paper["first_difference"]
    assert (paper["matched_poi_before"], paper["matched_poi_after"]) == (3, -1)
    assert paper["decision_changed"] is True
    changed = sum(bool(r["decision_changed"]) for r in rows.values())
    changes = "changes its" if changed == 1 else "change their"
    # paper-wind's look photo is taken where red scores 0.993: still a match
    assert rows["paper-wind.mcap"]["decision_changed"] is False
    assert (
        f"decisions      {changed} of {len(rows)} flights {changes} decision under the new"
        in result.output
    )


def test_a_folder_without_recordings_is_bad_input(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["replay", str(tmp_path)])
    assert result.exit_code == 2
    assert "no .mcap recordings there" in result.output
