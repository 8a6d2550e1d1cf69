"""Recordings are untrusted input: fuzzed with hypothesis, every reader either works or says
what is wrong in one line (a UavtoolError) — never a traceback — and a damaged file never
passes for a whole one.

Two targets: the metadata of a real flight's recording, one value replaced by something
hostile (deep JSON, numbers beyond any range, control characters, wrong types), read by
everything that reads a flight description (replay, re-fly's set-up, info, view); and the
bytes of a small real recording, one byte flipped or the file cut, read by info, replay and
export.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzzing import examples
from uavtool.cli import cli
from uavtool.errors import INCOMPLETE_EXIT, UavtoolError
from uavtool.recording import RecordingReader, RecordingWriter
from uavtool.recording.info import summarize
from uavtool.replay import load_flight, replay
from uavtool.replay.refly import refly_config

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"
_SETTINGS = settings(
    max_examples=examples(40),
    deadline=None,
    derandomize=True,  # the same examples on every run: a failure is reproducible
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def small_flight(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short real flight (take-off, one photo, landing): every topic a flight has."""
    path = tmp_path_factory.mktemp("fuzz") / "hop.mcap"
    args = ["fly", "-q", "--mission", "tests.plugins.hop:HopMission", "--set", "hop.photos=1"]
    result = CliRunner().invoke(cli, [*args, "--output", str(path)])
    assert result.exit_code == 0, result.output
    return path


def _golden_metadata() -> dict[str, dict[str, str]]:
    with RecordingReader(GOLDEN) as reader:
        return {name: dict(record) for name, record in reader.metadata if name != "uavtool"}


_META = _golden_metadata()
_FIELDS = sorted((name, key) for name, record in _META.items() for key in record)
_JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner),
    max_leaves=12,
)
_KNOWN_BAD = [
    "[" * 50_000 + "]" * 50_000,
    '{"a": ' * 20_000 + "1" + "}" * 20_000,
    "1e400",
    "-1e400",
    "0x" + "f" * 4_000,
    "9" * 5_000,
    "\x1b]52;c;aGk=\x07\u202e\x00",
    "[20000, 20000]",
    "[[0, 1e308]]",
    '"builtin"',
    "",
]
"""What the attack run of issue 30 tried, and its neighbours: each tried in every field."""
_HOSTILE = st.one_of(
    st.text(max_size=40),
    st.integers().map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    _JSON.map(json.dumps),
    st.sampled_from(_KNOWN_BAD),
)


def _crafted(path: Path, record: str, key: str, value: str) -> Path:
    """The golden's metadata with one value replaced, and a few of its observations and
    outputs: what a hostile recording could say, its CRCs right."""
    meta = {name: dict(fields) for name, fields in _META.items()}
    meta[record][key] = value
    with RecordingReader(GOLDEN) as reader, RecordingWriter(path, metadata=meta) as writer:
        writer.add_json_topic("/mission/observations", schema_name="x", schema={})
        writer.add_json_topic("/mission/outputs", schema_name="x", schema={})
        for n, entry in enumerate(reader.entries(["/mission/observations", "/mission/outputs"])):
            writer.write_json(entry.topic, entry.value.payload, log_time_ns=entry.log_time_ns)
            if n > 40:
                break
    return path


def _quietly(call: Any) -> None:
    """Run ``call``: a UavtoolError is a fine answer; anything else is a traceback."""
    try:
        call()
    except UavtoolError as exc:
        text = str(exc)
        assert "\n" not in text and "Traceback" not in text


def _read_everything(path: Path, work: Path) -> None:
    _quietly(lambda: replay(load_flight(path)))
    _quietly(lambda: refly_config(path, out=work / "again.mcap", workdir=work))
    _quietly(lambda: summarize(path))


@pytest.mark.parametrize("field", _FIELDS, ids=[f"{r}.{k}" for r, k in _FIELDS])
def test_every_field_refuses_what_an_attacker_tried(tmp_path: Path, field: tuple[str, str]) -> None:
    for i, value in enumerate(_KNOWN_BAD):
        path = _crafted(tmp_path / f"crafted-{i}.mcap", *field, value)
        _read_everything(path, tmp_path)


@_SETTINGS
@given(field=st.sampled_from(_FIELDS), value=_HOSTILE)
def test_hostile_metadata_is_refused_in_one_line(
    tmp_path_factory: pytest.TempPathFactory, field: tuple[str, str], value: str
) -> None:
    work = tmp_path_factory.mktemp("meta")
    path = _crafted(work / "crafted.mcap", *field, value)
    _read_everything(path, work)
    for args in (["info", str(path)], ["view", str(path), "--save", str(work / "v.rrd")]):
        result = CliRunner().invoke(cli, args)
        assert result.exit_code in (0, 1, 2), result.output
        assert not isinstance(result.exception, Exception) or isinstance(
            result.exception, SystemExit
        ), repr(result.exception)
        assert "\x1b]" not in result.output and "\u202e" not in result.output


@_SETTINGS
@given(data=st.data())
def test_a_damaged_recording_never_passes_for_whole(
    tmp_path_factory: pytest.TempPathFactory, small_flight: Path, data: st.DataObject
) -> None:
    size = small_flight.stat().st_size
    work = tmp_path_factory.mktemp("bytes")
    path = work / "damaged.mcap"
    shutil.copyfile(small_flight, path)
    raw = bytearray(path.read_bytes())
    if data.draw(st.booleans(), label="cut"):
        cut = data.draw(st.integers(0, size - 1), label="at")
        del raw[cut:]
    else:
        at = data.draw(st.integers(0, size - 1), label="at")
        raw[at] ^= data.draw(st.integers(1, 255), label="xor")
    path.write_bytes(bytes(raw))
    try:
        info = summarize(path)
    except UavtoolError:
        return  # refused as a whole: said, not passed
    whole = info.whole and not info.damage and not info.summary_problem
    assert not whole, "a damaged file passed for a whole one"
    replayed = CliRunner().invoke(
        cli, ["replay", "--check", str(path), "--mission", "tests.plugins.hop:HopMission"]
    )
    assert replayed.exit_code in (1, 2), replayed.output  # never 'identical' on a damaged file
    assert not isinstance(replayed.exception, Exception) or isinstance(
        replayed.exception, SystemExit
    ), repr(replayed.exception)
    if info.damage or not info.whole:  # messages lost: exported and shown only with a word
        for args in (
            ["export", "--tlog", str(work / "o.tlog")],
            ["view", "--save", str(work / "v.rrd")],
        ):
            result = CliRunner().invoke(cli, [args[0], str(path), *args[1:]])
            assert result.exit_code in (2, INCOMPLETE_EXIT), (args, result.output)
            assert not isinstance(result.exception, Exception) or isinstance(
                result.exception, SystemExit
            ), repr(result.exception)
