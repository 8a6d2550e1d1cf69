"""A recording's observations and outputs are untrusted input too: fuzzed with hypothesis,
one field of one message replaced by something hostile (infinity, NaN, a string for a
number, a number beyond any range, a missing value, a list for a mapping), every command that
reads them — ``view``, ``replay --check``, ``replay`` — either works or says what is wrong in
one line, exit 1 or 2. Never a traceback, never ``identical`` for an altered flight."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzzing import examples
from uavtool.cli import cli
from uavtool.recording import RecordingReader, RecordingWriter
from uavtool.recording.topics import IMAGE, OBSERVATIONS, OUTPUTS, TARGET

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"
_TOPICS = [OBSERVATIONS, OUTPUTS, IMAGE, TARGET]


def _golden() -> tuple[dict[str, dict[str, str]], list[tuple[str, int, Any]]]:
    with RecordingReader(GOLDEN) as reader:
        meta = {name: dict(record) for name, record in reader.metadata if name != "uavtool"}
        entries = [(e.topic, e.log_time_ns, e.value) for e in reader.entries(_TOPICS)]
    return meta, entries


_META, _ENTRIES = _golden()


def _first_of_each_type() -> list[int]:
    """Indexes (into _ENTRIES) of the first message of every observation and output type."""
    seen: dict[tuple[str, str], int] = {}
    for i, (topic, _, value) in enumerate(_ENTRIES):
        if topic in (OBSERVATIONS, OUTPUTS):
            seen.setdefault((topic, value.payload["type"]), i)
    return sorted(seen.values())


_TARGETS = _first_of_each_type()


def _fields(payload: dict[str, Any]) -> list[tuple[str, ...]]:
    """Paths to every field, and to every field one mapping or list deeper."""
    paths: list[tuple[str, ...]] = []
    for key, value in payload.items():
        paths.append((key,))
        if isinstance(value, dict):
            paths.extend((key, inner) for inner in value)
        elif isinstance(value, list) and value:
            paths.append((key, "0"))
    return paths


_HOSTILE: list[Any] = [
    float("inf"),
    float("-inf"),
    float("nan"),
    "x",
    None,
    True,
    [],
    {},
    -1,
    10**400,
    -(10**30),
    1e308,
    [[0.0, 0.0]],
    {"type": "Photo"},
]


def _set(payload: dict[str, Any], path: tuple[str, ...], value: Any) -> dict[str, Any]:
    out = json.loads(json.dumps(payload))
    holder: Any = out
    for key in path[:-1]:
        holder = holder[key]
    if isinstance(holder, list):
        holder[int(path[-1])] = value
    else:
        holder[path[-1]] = value
    return out


def _write(path: Path, index: int, payload: dict[str, Any]) -> Path:
    """The golden's mission streams, frames and target, message ``index`` replaced."""
    with RecordingWriter(path, metadata=_META) as writer:
        writer.add_json_topic(OBSERVATIONS, schema_name="uavtool.Observation", schema={})
        writer.add_json_topic(OUTPUTS, schema_name="uavtool.Output", schema={})
        for i, (topic, t_ns, value) in enumerate(_ENTRIES):
            if i == index:  # as a hostile writer would: Infinity and NaN too
                writer.write_json_bytes(topic, json.dumps(payload).encode(), log_time_ns=t_ns)
            elif topic in (OBSERVATIONS, OUTPUTS):
                writer.write_json(topic, value.payload, log_time_ns=t_ns)
            else:
                writer.write(topic, value, log_time_ns=t_ns)
    return path


def _run(args: list[str]) -> str:
    result = CliRunner().invoke(cli, args)
    assert result.exit_code in (0, 1, 2), (args, result.output)
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        args,
        repr(result.exception),
    )
    if result.exit_code == 2:
        assert len(result.output.strip().splitlines()) == 1, result.output
    return result.output


def _everything_reads(path: Path, work: Path, *, output_altered: bool) -> None:
    _run(["view", str(path), "--save", str(work / "v.rrd")])
    checked = _run(["replay", "--check", str(path)])
    if output_altered:  # the mission cannot have made it: never "identical"
        assert "identical" not in checked, checked
    if "observations replayed" not in checked:
        # --check refused before replaying (no Outcome, a cut file), and the plain replay reads
        # further. Once --check has replayed, the plain replay is the same code on the same
        # file, and its run would only double the test's time.
        _run(["replay", str(path)])


def test_the_unaltered_copy_reads_cleanly(tmp_path: Path) -> None:
    """The fuzz's base: the copy holds what the commands need, so a refusal is the change's."""
    index = _TARGETS[0]
    path = _write(tmp_path / "same.mcap", index, _ENTRIES[index][2].payload)
    out = _run(["replay", "--check", str(path)])
    assert "identical" in out
    assert "wrote" in _run(["view", str(path), "--save", str(tmp_path / "v.rrd")])


@pytest.mark.parametrize(
    ("kind", "value"),
    [("Photo", float("inf")), ("Photo", "7"), ("Photo", 10**400), ("Recognition", "x")],
    ids=["Photo-inf", "Photo-string", "Photo-huge", "Recognition-string"],
)
def test_a_frame_index_of_the_wrong_kind_is_one_line(tmp_path: Path, kind: str, value: Any) -> None:
    """The attack run's cases: a frame index of infinity or a string."""
    index = next(i for i in _TARGETS if _ENTRIES[i][2].payload["type"] == kind)
    payload = _set(_ENTRIES[index][2].payload, ("frame_index",), value)
    altered = _ENTRIES[index][0] == OUTPUTS
    _everything_reads(_write(tmp_path / "f.mcap", index, payload), tmp_path, output_altered=altered)


@settings(
    max_examples=examples(60),
    deadline=None,
    derandomize=True,  # the same examples on every run: a failure is reproducible
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_hostile_field_is_refused_in_one_line(
    tmp_path_factory: pytest.TempPathFactory, data: st.DataObject
) -> None:
    index = data.draw(st.sampled_from(_TARGETS), label="message")
    payload = _ENTRIES[index][2].payload
    field = data.draw(st.sampled_from(_fields(payload)), label="field")
    value = data.draw(st.sampled_from(_HOSTILE), label="value")
    work = tmp_path_factory.mktemp("content")
    crafted = _set(payload, field, value)
    path = _write(work / "crafted.mcap", index, crafted)
    altered = _ENTRIES[index][0] == OUTPUTS and json.dumps(crafted) != json.dumps(payload)
    _everything_reads(path, work, output_altered=altered)
