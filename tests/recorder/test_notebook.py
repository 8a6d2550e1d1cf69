"""notebooks/analyze_record.ipynb runs top to bottom on a flight recorded by `uavtool record`
(the session's recorded flight: no network, no committed recording)."""

from __future__ import annotations

import base64

import pytest

from tests.notebook import run_notebook
from tests.recorder.flight import STOPS, Recorded


def test_record_notebook_draws_route_photos_and_scores(
    recorded: Recorded, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("UAVTOOL_RECORDED", str(recorded.path))
    monkeypatch.delenv("UAVTOOL_TARGET", raising=False)  # the recorded scene's target
    outputs = run_notebook("analyze_record.ipynb", timeout_s=120)
    assert not [o for o in outputs if o["output_type"] == "error"]
    figures = [o["data"]["image/png"] for o in outputs if "image/png" in o.get("data", {})]
    assert len(figures) == 3  # route, photos with their shapes, scores
    assert all(base64.b64decode(f).startswith(b"\x89PNG") for f in figures)
    text = "".join(o.get("text", "") for o in outputs)
    assert f"{len(STOPS)} photos" in text
    assert "record_result: {'stopped': 'landed'" in text
    assert "mode GUIDED → AUTO" in text and "armed" in text  # the events, in order
    assert "1 match(es): [" in text  # the red building, as `replay --vision-only` finds it
    assert text.count("MATCH") == 1
