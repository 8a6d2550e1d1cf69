"""What the flight's, the replay's and the recording's writer processes import: a lockstep
flight takes about a second, and an import of trimesh (~0.15 s), numpy.ma (~20 ms, through
np.median or np.unique) or mcap's writer (~15 ms, for a replay that writes nothing) is a tenth
of it. The MCAP file is made by the recording's writer process, not by the flight's; that
process makes the frames' PNGs (`uavtool.png`) and the model's GLB (`uavtool.glb`) in plain
Python, without numpy (~0.1 s), OpenCV or trimesh."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_RUN = (
    "import sys\n"
    "poison, blocked, writer_blocked = sys.argv[1], sys.argv[2], sys.argv[3]\n"
    "for name in filter(None, writer_blocked.split(',')):\n"
    "    __import__(name)  # the flight's process has them before the poison\n"
    "sys.path.insert(0, poison)  # what a writer process, given this sys.path, would import\n"
    "for name in blocked.split(','):\n"
    "    sys.modules[name] = None  # importing it raises ImportError\n"
    "if sys.argv[4] == 'fly':\n"
    "    import uavtool.runner.fly as fly\n"
    "    fly.core_to_spare = lambda: True  # the writer process, whatever the machine's load\n"
    "from uavtool.cli import main\n"
    "sys.argv = ['uavtool', *sys.argv[4:]]\n"
    "main()\n"
)


def _uavtool(
    blocked: str, *args: str, cwd: Path, writer_blocked: str = ""
) -> subprocess.CompletedProcess[str]:
    """``uavtool ARGS`` with the modules ``blocked`` names unimportable in its process. A
    writer process gets a ``sys.path`` that starts with a folder of packages named as the
    top-level ones of ``blocked`` and ``writer_blocked``, which leave a mark in ``cwd`` when
    imported, then fail; the flight's process has imported ``writer_blocked`` before."""
    poison = cwd / "poisoned"
    for name in {*blocked.split(","), *writer_blocked.split(",")}:
        if name and "." not in name:
            (poison / name).mkdir(parents=True)
            (poison / name / "__init__.py").write_text(
                f"open({str(cwd / ('imported-' + name))!r}, 'w').close()\n"
                f"raise ImportError('{name} is blocked')\n"
            )
    return subprocess.run(
        [sys.executable, "-c", _RUN, str(poison), blocked, writer_blocked, *args],
        check=False,
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


@pytest.mark.slow
def test_a_recorded_flight_imports_no_trimesh_and_no_mcap_writer(tmp_path: Path) -> None:
    """With a writer process (a core to spare); on a busy machine the flight's own thread
    writes, and makes the GLB itself. The writer process imports neither numpy nor OpenCV."""
    run = _uavtool(
        "trimesh,numpy.ma,mcap.writer",
        "fly",
        "-o",
        str(tmp_path / "f.mcap"),
        cwd=tmp_path,
        writer_blocked="numpy,cv2",
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert sorted(p.name for p in tmp_path.glob("imported-*")) == []
    assert "completed: model built" in run.stdout
    assert "IoU vs ground truth 0.9" in run.stdout


def test_replay_check_imports_no_trimesh_and_no_writer(tmp_path: Path) -> None:
    golden = ROOT / "recordings" / "golden" / "paper.mcap"
    run = _uavtool("trimesh,numpy.ma,mcap.writer", "replay", "--check", str(golden), cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "identical" in run.stdout
