"""``uavtool sweep`` on a real 2-worker LocalCluster: the rows, the same table whatever the
workers, --resume, and a worker killed mid-sweep."""

from __future__ import annotations

import os
import shutil
import signal
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.cli.fly import EXIT_CODES
from uavtool.sweep import load_spec, run_sweep
from uavtool.sweep.errors import OutputExistsError
from uavtool.sweep.table import RUN_DEPENDENT, read_table

# Three short flights of the paper scene, and three whose link is cut from the start: the
# vehicle is never heard, the flight raises LinkError, and its row says so.
SPEC = """
[scenes]
builtin = ["paper"]

[grid]
seed = [0, 1, 2]
link_outages = [[], [[0, 100]]]
"""


def reproducible(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{k: v for k, v in r.items() if k not in RUN_DEPENDENT} for r in rows]


@pytest.fixture(scope="module")
def spec_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("spec") / "six.toml"
    path.write_text(SPEC)
    return path


@pytest.fixture(scope="module")
def swept(spec_path: Path, scheduler: str) -> Path:
    """The six flights, swept once through the command line on the 2-worker cluster."""
    out = spec_path.parent / "out"
    result = CliRunner().invoke(
        cli, ["sweep", str(spec_path), "--output", str(out), "--scheduler", scheduler, "-q"]
    )
    assert result.exit_code == 1, result.output  # three flights raised: rows with errors
    assert "flights        6 of 6" in result.output
    return out


def test_a_sweep_gives_one_row_per_flight(swept: Path) -> None:
    rows = read_table(swept / "results.parquet")
    assert [r["flight"] for r in rows] == list(range(6))
    assert [(r["seed"], r["link_outages"]) for r in rows] == [
        (s, o) for s in (0, 1, 2) for o in ("[]", "[[0.0, 100.0]]")
    ]
    flown, failed = rows[0::2], rows[1::2]
    for r in flown:
        assert (r["status"], r["exit_code"], r["error"]) == ("completed", 0, None)
        assert r["correct"] and r["matched_building"] == r["target_building"] == "red"
        assert r["iou"] > 0.8 and r["match_score"] >= 0.7
        assert r["margin"] is None  # red, the only one of the target's hue, was all it saw
        assert r["clearance_m"] > 0 and r["flight_time_s"] > 60 and r["frames"] >= 6
        assert r["worker"] in {"0", "1"} and r["wall_s"] > 0
        assert (swept / r["recording"]).stat().st_size == r["recording_bytes"]
    for r in failed:
        assert (r["status"], r["exit_code"]) == ("error", 2)
        assert r["error"].startswith("LinkError: ") and r["correct"] is None
    summary = (swept / "summary.txt").read_text()
    assert "correct match  3/6 (50 %)" in summary and "by link_outages:" in summary
    plots = {p.name for p in (swept / "plots").glob("*.png")}
    assert "iou.png" in plots and "margin.png" not in plots  # no flight saw another building
    assert not list(swept.rglob("*.part"))


def test_the_table_is_the_same_with_one_worker_and_a_small_window(
    swept: Path, spec_path: Path, tmp_path: Path
) -> None:
    # A window of 2 tasks on the scheduler: the rest are submitted as those finish.
    result = run_sweep(
        load_spec(spec_path),
        exit_codes=EXIT_CODES,
        out=tmp_path / "one",
        workers=1,
        plots=False,
        window=2,
    )
    assert {r["worker"] for r in result.rows if r["status"] != "error"} == {"0"}
    assert reproducible(read_table(result.table)) == reproducible(
        read_table(swept / "results.parquet")
    )


def test_resume_refuses_another_sweep_and_changes_nothing(
    swept: Path, spec_path: Path, tmp_path: Path
) -> None:
    """The issue's case: a sweep resumed without its override (or with another spec) was
    replaced by a different one: the table, spec.toml, and clashing flight numbers."""
    out = tmp_path / "kept"
    shutil.copytree(swept, out)
    before = {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    other = load_spec(spec_path, ["grid.seed=[7, 8, 9]"])
    with pytest.raises(OutputExistsError, match="holds another sweep") as exc:
        run_sweep(other, exit_codes=EXIT_CODES, out=out, resume=True, plots=False)
    assert "--set values it was started with" in str(exc.value)
    after = {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    assert after == before  # not a byte changed
    (out / "plan.json").unlink()  # a folder from before plans were kept: the spec's text
    with pytest.raises(OutputExistsError, match=r"its spec.toml differs"):
        run_sweep(other, exit_codes=EXIT_CODES, out=out, resume=True, plots=False)


def test_resume_flies_only_what_is_missing(
    swept: Path, spec_path: Path, tmp_path: Path, scheduler: str
) -> None:
    out = tmp_path / "resumed"
    shutil.copytree(swept, out)
    before = read_table(out / "results.parquet")
    (out / before[0]["recording"]).unlink()  # never finished
    cut = out / before[2]["recording"]
    cut.write_bytes(cut.read_bytes()[: cut.stat().st_size // 2])  # killed while writing
    kept = out / before[4]["recording"]
    stamp = kept.stat().st_mtime_ns
    (out / "results.parquet").unlink()
    with pytest.raises(Exception, match="--resume"):
        run_sweep(load_spec(spec_path), exit_codes=EXIT_CODES, out=out, plots=False)

    result = run_sweep(
        load_spec(spec_path),
        exit_codes=EXIT_CODES,
        out=out,
        resume=True,
        plots=False,
        scheduler=scheduler,
    )
    # Kept: the whole recordings left (flight 4, and those of the flights that raised if
    # their recording was written); flown again: flights 0 and 2, and any error without one.
    whole = [r["flight"] for r in before if r["recording"] and r["flight"] not in (0, 2)]
    assert 4 in whole
    assert (result.flown, result.resumed) == (6 - len(whole), len(whole))
    assert kept.stat().st_mtime_ns == stamp
    assert reproducible(read_table(result.table)) == reproducible(before)


def test_a_worker_killed_mid_sweep_still_gives_a_complete_table(
    tmp_path: Path, scheduler: str, cluster: Any
) -> None:
    from distributed import Client

    path = tmp_path / "four.toml"
    path.write_text('[scenes]\nbuiltin = ["paper"]\n[grid]\nseed = [10, 11, 12, 13]\n')
    done: dict[str, Any] = {}

    def sweep() -> None:
        done["result"] = run_sweep(
            load_spec(path),
            exit_codes=EXIT_CODES,
            out=tmp_path / "out",
            scheduler=scheduler,
            plots=False,
        )

    with Client(scheduler) as client:
        pids = client.run(os.getpid)
        thread = threading.Thread(target=sweep)
        thread.start()
        victim = _busy_worker(client, since_s=0.3)
        os.kill(pids[victim], signal.SIGKILL)
        thread.join(timeout=120)
        client.wait_for_workers(2, timeout=60)  # the nanny restarts it for later tests
    result = done["result"]
    # The flight on the killed worker was started twice: the scheduler gave it to another.
    started: dict[str, int] = {}
    for key, _start, finish, *_ in cluster.scheduler.transition_log:
        if str(key).startswith("flight-") and finish == "processing":
            started[str(key)] = started.get(str(key), 0) + 1
    assert max(started.values()) >= 2, started
    assert [r["status"] for r in result.rows] == ["completed"] * 4
    assert all(
        (result.root / r["recording"]).stat().st_size == r["recording_bytes"] for r in result.rows
    )
    assert not list(result.root.rglob("*.part"))


def _busy_worker(client: Any, *, since_s: float) -> str:
    """A worker that has been running a flight for ``since_s``."""
    seen: dict[str, float] = {}
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        for worker, keys in client.processing().items():
            if any(str(k).startswith("flight-") for k in keys):
                first = seen.setdefault(worker, time.monotonic())
                if time.monotonic() - first >= since_s:
                    return str(worker)
        time.sleep(0.05)
    raise AssertionError("no flight started")


def test_a_timeout_a_csv_table_and_no_matplotlib(
    tmp_path: Path, scheduler: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A flight past --timeout (vehicle seconds) is a row with its error; --csv writes the
    table as CSV; without matplotlib the sweep says it skipped the plots and still succeeds
    in writing the rest. --resume keeps the stopped flight under the same limit only."""
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)  # import fails
    path = tmp_path / "one.toml"
    path.write_text('[scenes]\nbuiltin = ["paper"]\n')
    out = tmp_path / "out"
    args = ["sweep", str(path), "--output", str(out), "--scheduler", scheduler, "--csv", "-q"]
    result = CliRunner().invoke(cli, [*args, "--timeout", "30"])
    assert result.exit_code == 1, result.output
    assert "plots skipped: matplotlib is not installed" in result.output
    assert not (out / "results.parquet").exists() and not list(out.glob("plots/*.png"))
    (row,) = read_table(out / "results.csv")
    assert row["status"] == "error" and row["timeout_s"] == 30.0
    assert row["error"] == (
        "FlightTimeoutError: stopped after 30 s of vehicle time (sweep.timeout_s)"
    )
    assert (out / row["recording"]).stat().st_size == row["recording_bytes"]

    again = CliRunner().invoke(cli, [*args, "--timeout", "30", "--resume"])
    assert "flights        1 of 1" in again.output
    assert read_table(out / "results.csv") == [row]  # kept: nothing flown
    longer = CliRunner().invoke(cli, [*args, "--timeout", "40", "--resume"])
    assert longer.exit_code == 1, longer.output
    (row,) = read_table(out / "results.csv")
    assert row["timeout_s"] == 40.0 and "after 40 s" in row["error"]
