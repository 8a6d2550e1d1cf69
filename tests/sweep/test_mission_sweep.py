"""A sweep of another mission: ``[sweep] mission`` names it, ``set.*`` are its parameters,
and the table, summary and recordings are its own."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.recording import RecordingReader
from uavtool.sweep.table import read_table

SPEC = """
[sweep]
mission = "orbit"
[scenes]
builtin = ["paper"]
[grid]
"set.orbit.step_deg" = [120, 180]
"""


def test_a_sweep_flies_the_mission_it_names(tmp_path: Path, scheduler: str) -> None:
    spec = tmp_path / "orbit.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    args = ["sweep", str(spec), "--output", str(out), "--scheduler", scheduler, "-q"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "correct match" not in result.output  # the search's findings: not this mission's
    assert "  120                    completed 1/1 (100 %)" in result.output, result.output
    rows = read_table(out / "results.parquet")
    assert [(r["set.orbit.step_deg"], r["status"], r["frames"]) for r in rows] == [
        (120, "completed", 3),
        (180, "completed", 2),
    ]
    for row in rows:
        with RecordingReader(out / row["recording"]) as reader:
            mission = dict(reader.metadata)["mission"]
        assert mission["name"] == "orbit"


def test_a_parameter_of_another_mission_is_refused_by_name(tmp_path: Path) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(SPEC.replace("set.orbit.step_deg", "set.mission.look_fill"))
    result = CliRunner().invoke(cli, ["sweep", str(spec), "--output", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "unknown mission parameter 'mission.look_fill'" in result.output, result.output
    spec.write_text(SPEC.replace('"orbit"', '"nosuch"'))
    result = CliRunner().invoke(cli, ["sweep", str(spec), "--output", str(tmp_path / "o")])
    assert result.exit_code == 2 and "sweep.mission" in result.output, result.output
    assert "no such mission" in result.output and "Traceback" not in result.output


FLEET = """
[sweep]
mission = "fleet-survey"
[scenes]
builtin = ["paper"]
[grid]
vehicles = [1, 3]
"""


def test_vehicles_is_a_sweep_dimension(tmp_path: Path, scheduler: str) -> None:
    spec = tmp_path / "fleet.toml"
    spec.write_text(FLEET)
    out = tmp_path / "out"
    args = ["sweep", str(spec), "--output", str(out), "--scheduler", scheduler, "-q"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "by vehicles:" in result.output and "median" in result.output
    assert "0 flights closer than its separation" in result.output
    rows = read_table(out / "results.parquet")
    assert [(r["vehicles"], r["status"]) for r in rows] == [(1, "completed"), (3, "completed")]
    assert rows[0].get("closest_approach_m") is None and rows[1]["closest_approach_m"] >= 5.0
    with RecordingReader(out / rows[1]["recording"]) as reader:
        assert dict(reader.metadata)["fleet"]["vehicles"] == "3"


def test_a_fleet_of_a_one_vehicle_mission_is_refused_by_the_spec(tmp_path: Path) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(FLEET.replace("fleet-survey", "orbit"))
    result = CliRunner().invoke(cli, ["sweep", str(spec), "--output", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert "vehicles: 3 vehicles: the mission 'orbit' flies one" in result.output
