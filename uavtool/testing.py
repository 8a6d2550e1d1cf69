"""A pytest plugin: your recordings become regression tests (one vehicle's or a fleet's).

Enabled automatically when uavtool is installed. Name folders of ``.mcap`` files in your
pytest configuration::

    [tool.pytest.ini_options]
    uavtool_recordings = ["recordings/golden", "tests/flights"]

and write one test that takes the ``uavtool_recording`` argument; it runs once per file::

    from uavtool.testing import assert_replays_identically

    def test_recording_replays(uavtool_recording):
        assert_replays_identically(uavtool_recording)

Recordings of your own mission work the same once its package is installed (registered in
the ``uavtool.missions`` entry-point group); else pass ``mission="module:Class"``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

_INI = "uavtool_recordings"


def pytest_addoption(parser: Any) -> None:
    parser.addini(_INI, "folders whose .mcap recordings uavtool_recording runs over", type="paths")


def recordings(config: Any) -> list[Path]:
    """Every ``.mcap`` in the configured folders, sorted."""
    out: list[Path] = []
    for folder in config.getini(_INI):
        out.extend(sorted(Path(folder).glob("*.mcap")))
    return out


def pytest_generate_tests(metafunc: Any) -> None:
    if "uavtool_recording" in metafunc.fixturenames:
        paths = recordings(metafunc.config)
        metafunc.parametrize("uavtool_recording", paths, ids=[p.name for p in paths])


def assert_replays_identically(path: str | Path, *, mission: str | None = None) -> None:
    """Replay ``path`` with its recorded parameters; AssertionError with the first difference
    (step, output, field, recorded vs replayed) unless every output is equal. ``mission``
    (``module:Class``) names the mission's class when it is not registered (installed)."""
    from uavtool.replay import load_flight, replay  # noqa: PLC0415 - keep pytest start-up light
    from uavtool.replay.fleet import replay_fleet  # noqa: PLC0415
    from uavtool.replay.load import is_fleet, load_fleet  # noqa: PLC0415

    if is_fleet(path):  # a fleet's: each vehicle's outputs, "uavK: " before a difference
        fleet = load_fleet(path, mission=mission)
        results = replay_fleet(fleet)
        named = [(f"uav{v.sysid}: ", r) for v, r in zip(fleet.vehicles, results, strict=True)]
    else:
        named = [("", replay(load_flight(path, mission=mission)))]
    for who, result in named:
        if result.first_difference is not None:
            raise AssertionError(f"{path}: {who}{result.first_difference.describe()}")
        if result.divergence is not None:
            raise AssertionError(
                f"{path}: {who}diverged at step {result.divergence.step}: "
                f"{result.divergence.reason}"
            )


def assert_reflies_identically(path: str | Path, *, mission: str | None = None) -> None:
    """Fly ``path``'s configuration again on the built-in vehicle, in lockstep, and compare the
    new recording with it; AssertionError with the first difference. Only for recordings
    made by ``uavtool fly`` on the built-in vehicle; ``mission`` as above."""
    from uavtool.replay.refly import refly  # noqa: PLC0415 - keep pytest start-up light

    result = refly(path, mission=mission)
    if result.first_difference is not None:
        raise AssertionError(f"{path}: re-flown: {result.first_difference}")
