"""A mission recording for the viewer tests: the golden one when it exists, else one flight
of ``uavtool fly`` on the paper scene per test session (~10 s)."""

from __future__ import annotations

import subprocess
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.view.rrd import Store, read_rrd
from uavtool.cli import cli
from uavtool.recording import RecordingReader

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "recordings" / "golden" / "paper.mcap"


@dataclass(frozen=True)
class Facts:
    """What the recording holds, counted from the MCAP itself."""

    frames: int
    telemetry: int
    shapes: int
    strips: int
    model_vertices: int
    statustexts: int
    recognitions: int
    pois: int
    matched_poi: int | None


@pytest.fixture(scope="session")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if GOLDEN.exists():
        return GOLDEN
    out = tmp_path_factory.mktemp("fly") / "paper.mcap"
    proc = subprocess.run(
        [sys.executable, "-m", "uavtool", "fly", "--scene", "paper", "--output", str(out), "-q"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, f"uavtool fly failed:\n{proc.stdout}\n{proc.stderr}"
    return out


@pytest.fixture(scope="session")
def facts(recording: Path) -> Facts:
    kinds: Counter[str] = Counter()
    shapes = strips = vertices = pois = 0
    matched = None
    with RecordingReader(recording) as reader:
        for entry in reader.entries(["/mission/observations", "/mission/outputs"]):
            d = entry.value.payload
            kind = d["type"]
            if kind == "Telemetry" and d["time_boot_ms"] > 0:
                kinds["telemetry"] += 1
            elif kind == "Shapes":
                shapes += len(d["shapes"])
                strips += sum(1 + len(s["holes_px"]) for s in d["shapes"])
            elif kind == "ModelBuilt":
                vertices = len(d["vertices_m"])
            elif kind == "Plan":
                pois = len(d["pois"])
            elif kind == "Recognition":
                kinds["recognitions"] += 1
                matched = d["poi"] if d["matched"] else matched
        counts = {reader.channels[i].topic: n for i, n in reader.message_counts.items()}
    return Facts(
        frames=counts["/camera/image"],
        telemetry=kinds["telemetry"],
        shapes=shapes,
        strips=strips,
        model_vertices=vertices,
        statustexts=counts.get("/mavlink/in/STATUSTEXT", 0),
        recognitions=kinds["recognitions"],
        pois=pois,
        matched_poi=matched,
    )


@dataclass(frozen=True)
class Saved:
    path: Path
    stdout: str
    data: Store
    blueprint: Store


@pytest.fixture(scope="session")
def saved(recording: Path, tmp_path_factory: pytest.TempPathFactory) -> Saved:
    """``uavtool view REC --save out.rrd``, read back with Rerun's reader."""
    out = tmp_path_factory.mktemp("view") / "paper.rrd"
    result = CliRunner().invoke(cli, ["view", str(recording), "--save", str(out)])
    assert result.exit_code == 0, result.output
    data, blueprint = read_rrd(out)
    return Saved(out, result.stdout, data, blueprint)
