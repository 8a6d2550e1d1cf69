"""Run a notebook of ``notebooks/`` top to bottom, as Jupyter would, for its outputs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"


def run_notebook(name: str, *, timeout_s: int) -> list[dict[str, Any]]:
    """Every output of every cell of ``notebooks/NAME`` once executed (in its own folder)."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    path = NOTEBOOKS / name
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        timeout=timeout_s,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
    )
    client.execute()
    return [o for c in nb.cells for o in c.get("outputs", [])]
