"""Plug-in missions: flown, recorded, replayed and re-flown exactly as the built-in one; found
by name through the entry-point group of an installed package; a missing or broken one is a
one-line error."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

import uavtool.api
from uavtool.cli import cli
from uavtool.plugins import PluginError
from uavtool.recording import RecordingReader
from uavtool.testing import assert_reflies_identically, assert_replays_identically

HOP = "tests.plugins.hop:HopMission"
ROOT = Path(__file__).parents[2]


def _run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.output


def _metadata(path: Path) -> dict[str, dict[str, str]]:
    with RecordingReader(path) as reader:
        return dict(reader.metadata)


def test_a_plugin_flies_records_replays_and_re_flies(tmp_path: Path) -> None:
    rec = tmp_path / "hop.mcap"
    code, out = _run("fly", "-q", "--mission", HOP, "--set", "hop.photos=3", "--output", str(rec))
    assert code == 0, out
    assert "completed: 3 photos" in out and 'result         hop: {"frames": [0, 1, 2]}' in out
    mission = _metadata(rec)["mission"]
    assert (mission["name"], mission["class"]) == (HOP, HOP)
    assert json.loads(mission["params"])["hop"]["photos"] == 3
    # A recording never makes uavtool import what it names: the class must be registered, or
    # named on the command line.
    code, out = _run("replay", "--check", str(rec))
    assert code == 2 and "not registered here" in out and f"--mission {HOP}" in out, out
    assert "Traceback" not in out
    code, out = _run("replay", "--check", str(rec), "--mission", HOP)
    assert code == 0 and "identical: every output equals the recorded one" in out, out
    code, out = _run("replay", str(rec), "--mission", HOP, "--set", "hop.photos=2")
    assert "diverged" in out or "first difference" in out, out
    code, out = _run("replay", "--refly", str(rec), "--mission", HOP)
    assert code == 0 and "identical: the new recording equals the old one" in out, out


def test_the_pytest_helpers_take_a_plugin_mission(tmp_path: Path) -> None:
    rec = tmp_path / "hop.mcap"
    assert _run("fly", "-q", "--mission", HOP, "--output", str(rec))[0] == 0
    assert_replays_identically(rec, mission=HOP)
    assert_reflies_identically(rec, mission=HOP)
    with pytest.raises(PluginError, match="not registered here"):
        assert_replays_identically(rec)


def test_the_api_example_flies(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The mission in uavtool.api's docstring, as a user would paste it into a module."""
    doc = uavtool.api.__doc__ or ""
    code = textwrap.dedent(doc.split("::\n", 1)[1].split("\n\n``uavtool fly")[0])
    (tmp_path / "my_hop.py").write_text(code)
    monkeypatch.syspath_prepend(str(tmp_path))
    rec = tmp_path / "doc.mcap"
    exit_code, out = _run(
        "fly", "-q", "--mission", "my_hop:HopMission", "--set", "hop.altitude_m=15",
        "--output", str(rec),
    )  # fmt: skip
    assert exit_code == 0, out
    assert "completed: one photo, frame 0" in out


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        (
            "nosuch",
            "no such mission; registered: fleet-search, fleet-survey, orbit, search, survey",
        ),
        ("no_such_module:Mission", "cannot import no_such_module"),
        ("tests.plugins.hop:Missing", "tests.plugins.hop has no Missing"),
        ("tests.plugins.hop:NotAMission", "is not a mission (subclass uavtool.api.FlightMission)"),
        ("tests.plugins.hop:BrokenStart", "could not start: RuntimeError: no camera calibration"),
    ],
)
def test_a_missing_or_broken_plugin_is_one_line(spec: str, words: str) -> None:
    code, out = _run("fly", "--no-record", "--mission", spec)
    assert code == 2, out
    assert words in out, out
    assert "Traceback" not in out and len(out.strip().splitlines()) == 1, out


def test_a_bug_in_the_mission_stops_the_run_and_sends_the_vehicle_home(tmp_path: Path) -> None:
    rec = tmp_path / "bug.mcap"
    code, out = _run(
        "fly", "-q", "--mission", HOP, "--set", "hop.fail_at_photo=1", "--output", str(rec)
    )
    assert code == 1, out
    assert "the mission raised ZeroDivisionError: integer division or modulo by zero" in out
    assert "hop.py:" in out and "Traceback" not in out
    assert _metadata(rec)["outcome"]["status"] == "failed"
    with RecordingReader(rec) as reader:
        sent = [e.value.payload for e in reader.entries(["/mavlink/out/COMMAND_LONG"])]
    # The last command: RTL (MAV_CMD_DO_SET_MODE to ArduCopter's mode 6)
    assert sent[-1]["command"] == 176 and sent[-1]["param2"] == 6.0, sent[-1]


def test_missions_lists_the_builtin_ones_and_their_parameters() -> None:
    code, out = _run("missions")
    assert code == 0, out
    names = [line.split()[0] for line in out.splitlines()]
    assert names[:3] == ["search", "survey", "orbit"], out
    code, out = _run("missions", "orbit")
    assert code == 0 and "orbit.step_deg = 45.0" in out and "flight.arrive_radius_m" in out


def test_the_search_rejects_options_of_its_own_for_other_missions() -> None:
    code, out = _run("fly", "--no-record", "--mission", "orbit", "--visit-all")
    assert code == 2 and "has no mission.visit_all" in out, out
    code, out = _run("fly", "--no-record", "--mission", "orbit", "--set", "orbit.radius=3")
    assert code == 2 and "did you mean orbit.radius_m" in out, out
    code, out = _run("fly", "--no-record", "--mission", "orbit", "--set", "orbit.aim_m=99")
    assert code == 2 and "orbit.aim_m must be below orbit.altitude_m" in out, out


def _install_package(site: Path) -> None:
    """A package installed the way pip installs one: its module, and a dist-info with the
    entry point in uavtool's group."""
    (site / "hop_pkg").mkdir()
    (site / "hop_pkg" / "__init__.py").write_text((ROOT / "tests/plugins/hop.py").read_text())
    info = site / "hop_pkg-1.2.3.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: hop-pkg\nVersion: 1.2.3\n")
    (info / "entry_points.txt").write_text("[uavtool.missions]\nhop = hop_pkg:HopMission\n")
    (info / "top_level.txt").write_text("hop_pkg\n")
    (info / "RECORD").write_text("")


def test_an_installed_package_registers_a_mission_by_name(tmp_path: Path) -> None:
    site = tmp_path / "site"
    site.mkdir()
    _install_package(site)
    env = {**os.environ, "PYTHONPATH": str(site)}
    rec = tmp_path / "hop.mcap"

    def uavtool_cli(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "uavtool", *args],
            env=env,
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )

    listed = uavtool_cli("missions")
    assert "hop" in listed.stdout and "[hop-pkg: hop_pkg:HopMission]" in listed.stdout, listed
    flown = uavtool_cli("fly", "-q", "--mission", "hop", "--output", str(rec))
    assert flown.returncode == 0, flown.stderr
    mission = _metadata(rec)["mission"]
    assert (mission["name"], mission["class"], mission["version"]) == (
        "hop",
        "hop_pkg:HopMission",
        "1.2.3",
    )
    checked = uavtool_cli("replay", "--check", str(rec))  # registered: no --mission needed
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "identical" in checked.stdout
