"""Sweep specs are untrusted input too: fuzzed with hypothesis (any TOML data in any of the
spec's tables, and text that is barely TOML), reading one either gives a spec or a one-line
SpecError — never a traceback, never a plan larger than the limit."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from tests.fuzzing import examples
from uavtool.errors import UavtoolError
from uavtool.sweep.plan import MAX_FLIGHTS, flight_count, plan_flights
from uavtool.sweep.spec import load_spec, parse_spec

_SCALAR = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(10**20), max_value=10**20)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=12)
)
_VALUE = st.recursive(
    _SCALAR.filter(lambda v: v is not None),
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=10), inner),
    max_leaves=15,
)
_KEYS = st.sampled_from(
    [
        "seed",
        "wind_speed_ms",
        "wind_from_deg",
        "noise",
        "link_outages",
        "home_heading_deg",
        "set.mission.look_fill",
        "set.recognize.threshold",
        "param.WPNAV_SPEED",
        "builtin",
        "files",
        "hard",
        "random",
        "draws",
        "rng_seed",
        "out",
        "format",
        "retries",
        "timeout_s",
        "mission",
        "nosuch",
    ]
)
_TABLE = st.dictionaries(_KEYS, _VALUE, max_size=4)
_SPEC = st.fixed_dictionaries(
    {},
    optional={
        "sweep": _TABLE,
        "scenes": _TABLE,
        "grid": _TABLE,
        "random": _TABLE,
        "cases": st.lists(_TABLE, max_size=3),
    },
)
_SETTINGS = settings(
    max_examples=examples(300),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def _read(call: Any) -> Any:
    try:
        return call()
    except UavtoolError as exc:
        message = str(exc)
    assert "\n" not in message  # one line
    return None


@_SETTINGS
@given(data=_SPEC)
@example(data={"sweep": {"format": []}})  # found in CI: a TypeError before
def test_any_spec_data_is_a_spec_or_one_line(tmp_path: Path, data: dict[str, Any]) -> None:
    spec = _read(lambda: parse_spec(data, source="fuzz.toml", base=tmp_path, default_out=tmp_path))
    if spec is not None and flight_count(spec) <= 2_000:
        flights = _read(lambda: plan_flights(spec))
        assert flights is None or len(flights) <= MAX_FLIGHTS


@_SETTINGS
@given(text=st.text(alphabet='[]{}"=.,\n 0123456789abcdefgrids_xyz#', max_size=200))
def test_any_text_is_a_spec_or_one_line(tmp_path: Path, text: str) -> None:
    path = tmp_path / "fuzz.toml"
    path.write_text(text)
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        with pytest.raises(UavtoolError):
            load_spec(path)
        return
    _read(lambda: load_spec(path))
