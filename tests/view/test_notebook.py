"""notebooks/analyze_recording.ipynb runs top to bottom on the test recording."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.notebook import run_notebook


def test_notebook_runs_and_draws_every_figure(
    recording: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("UAVTOOL_RECORDING", str(recording))
    outputs = run_notebook("analyze_recording.ipynb", timeout_s=180)
    figures = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(figures) == 4  # route, overview frame, scores, model
    errors = [o for o in outputs if o["output_type"] == "error"]
    assert not errors
    text = "".join(o.get("text", "") for o in outputs)
    assert "outcome: {'status': 'completed'" in text
