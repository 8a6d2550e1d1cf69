"""What the flight's and the replay's own processes import: a lockstep flight takes about a
second, and an import of trimesh (~0.1 s), numpy.ma (~20 ms, through np.median or np.unique)
or mcap's writer (~30 ms, for a replay that writes nothing) is a tenth of it. The model's GLB,
and the MCAP file itself, are made by the recording's writer process, not by the flight's."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_RUN = (
    "import sys\n"
    "for name in sys.argv[1].split(','):\n"
    "    sys.modules[name] = None  # importing it raises ImportError\n"
    "if sys.argv[2] == 'fly':\n"
    "    import uavtool.runner.fly as fly\n"
    "    fly.core_to_spare = lambda: True  # the writer process, whatever the machine's load\n"
    "from uavtool.cli import main\n"
    "sys.argv = ['uavtool', *sys.argv[2:]]\n"
    "main()\n"
)


def _uavtool(blocked: str, *args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", _RUN, blocked, *args],
        check=False,
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


@pytest.mark.slow
def test_a_recorded_flight_imports_no_trimesh_and_no_mcap_writer(tmp_path: Path) -> None:
    """With a writer process (a core to spare); on a busy machine the flight's own thread
    writes, and makes the GLB itself."""
    run = _uavtool(
        "trimesh,numpy.ma,mcap.writer", "fly", "-o", str(tmp_path / "f.mcap"), cwd=tmp_path
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "completed: model built" in run.stdout
    assert "IoU vs ground truth 0.9" in run.stdout


def test_replay_check_imports_no_trimesh_and_no_writer(tmp_path: Path) -> None:
    golden = ROOT / "recordings" / "golden" / "paper.mcap"
    run = _uavtool("trimesh,numpy.ma,mcap.writer", "replay", "--check", str(golden), cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "identical" in run.stdout
