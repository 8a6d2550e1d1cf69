"""Ctrl-C at a terminal: SIGINT reaches the whole foreground job, the local cluster's worker
processes included. The sweep stops with exit 130 and no traceback, its folder holds only
whole files and a table of what finished, and --resume flies the rest."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.sweep.table import read_table

SPEC = '[scenes]\nbuiltin = ["paper"]\n[grid]\nseed = [30, 31, 32]\n'


def test_ctrl_c_exits_130_quietly_and_resume_completes(tmp_path: Path, scheduler: str) -> None:
    spec = tmp_path / "three.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "uavtool", "sweep", str(spec), "--output", str(out)]
    sweep = subprocess.Popen(
        [*command, "--workers", "1", "-q"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a terminal's foreground job
    )
    try:
        _wait_for(lambda: any(out.glob("flights/*/*.json")), timeout_s=120)
        os.killpg(sweep.pid, signal.SIGINT)  # what Ctrl-C does: to every process of the job
        stdout, stderr = sweep.communicate(timeout=120)
    finally:
        if sweep.poll() is None:
            os.killpg(sweep.pid, signal.SIGKILL)
    assert sweep.returncode == 130, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    # Nor the cluster's shutdown, logged by Dask, Tornado or asyncio in the driver or a worker
    # (the scheduler that cannot gather a cancelled key, a closed TLS stream).
    assert not re.search(r"\b(ERROR|CRITICAL|distributed|tornado|asyncio)\b", stderr), stderr
    # The hint is the whole command that resumes: the spec, the folder, and then --resume.
    assert f"continue with: uavtool sweep {spec} --output {out} --workers 1 --resume" in stderr
    # No worker process outlives the command.
    _wait_for(lambda: not _live_processes(sweep.pid), timeout_s=30)

    # Consistent: only whole files, and the table lists exactly the flights whose recording
    # and row are there.
    assert not [p for p in out.rglob("*") if p.name.endswith((".part", ".partial"))]
    rows = read_table(out / "results.parquet")
    assert 1 <= len(rows) < 3, stdout
    assert sorted(p.stem for p in out.glob("flights/*/*.mcap")) == sorted(
        Path(r["recording"]).stem for r in rows
    )
    for r in rows:
        assert (out / r["recording"]).stat().st_size == r["recording_bytes"]
    assert f"flights        {len(rows)} of 3 (incomplete)" in stdout

    resumed = CliRunner().invoke(
        cli, ["sweep", str(spec), "--output", str(out), "--resume", "--scheduler", scheduler, "-q"]
    )
    assert resumed.exit_code == 0, resumed.output
    assert "flights        3 of 3\n" in resumed.output
    done = read_table(out / "results.parquet")
    assert [r["seed"] for r in done] == [30, 31, 32]
    assert {r["status"] for r in done} == {"completed"}
    assert [r for r in done if r["flight"] in {k["flight"] for k in rows}] == rows


def _wait_for(condition: Callable[[], bool], *, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.1)


def _live_processes(group: int) -> list[str]:
    """Processes of the group that still run (zombies wait for a reaper, not for us)."""
    ps = subprocess.run(
        ["ps", "-o", "stat=", "-g", str(group)], capture_output=True, text=True, check=False
    )
    return [s for s in ps.stdout.split() if not s.startswith("Z")]
