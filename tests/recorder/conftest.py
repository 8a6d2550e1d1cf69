"""One flight recorded by `uavtool record` per test session (~10 s), shared by the tests that
analyse such a file: the recorder's own, `info`, batch replay and the notebook."""

from __future__ import annotations

import pytest

from tests.recorder.flight import Recorded, record_auto_flight


@pytest.fixture(scope="session")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    return record_auto_flight(tmp_path_factory.mktemp("record") / "auto.mcap")
