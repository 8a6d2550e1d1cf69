"""The documentation says what the code does: the recording format's topic table is the set of
topics the code writes, with the encodings and schemas the recordings hold; the README's
command table is the CLI's; the exit codes in the tables are `uavtool fly`'s; every `uavtool`
command line in README.md and docs/ names commands and options that exist; the links between
the pages resolve; and the mission example in docs/missions.md flies."""

from __future__ import annotations

import re
import shlex
import textwrap
from collections.abc import Iterator
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.cli.fly import EXIT_CODES
from uavtool.geo import GeoPoint
from uavtool.recorder.sink import PassiveRecorder
from uavtool.recording import RecordingReader, RecordingWriter, annotations, topics
from uavtool.recording.annotations import copy_with_detections
from uavtool.recording.fleet import split_topic
from uavtool.recording.schemas import MAVLINK_RAW, mavlink_topic
from uavtool.recording.values import Direction

ROOT = Path(__file__).parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
FORMAT = DOCS / "recording-format.md"
GOLDEN = sorted((ROOT / "recordings" / "golden").glob("*.mcap"))
PAGES = [README, *sorted(DOCS.glob("*.md")), ROOT / "benchmarks" / "README.md"]
MSG = "<MSG>"  # how the topic table writes a MAVLink message's name


# --- reading Markdown ---------------------------------------------------------------------


def _section(path: Path, heading: str) -> str:
    """The text under ``## heading`` up to the next heading of that level or above."""
    text = path.read_text(encoding="utf-8")
    match = re.search(rf"^(#+) {re.escape(heading)}\n(.*?)(?=^#{{1,2}} |\Z)", text, re.M | re.S)
    assert match, f"{path.name}: no section {heading!r}"
    return match.group(2)


def _table(text: str) -> list[list[str]]:
    """The first Markdown table in ``text``: its rows (header and rule left out) as cells."""
    match = re.search(r"^\|.*\n(?:\|.*\n?)+", text, re.M)
    assert match, "no table"
    rows = match.group(0).splitlines()[2:]
    return [[c.strip() for c in re.split(r"(?<!\\)\|", row)[1:-1]] for row in rows]


def _code(cell: str) -> list[str]:
    """The `code spans` of a table cell."""
    return re.findall(r"`([^`]+)`", cell)


# --- the recording format's topic table ---------------------------------------------------


def _documented_topics() -> dict[str, tuple[str, str]]:
    """Topic → (message encoding, schema name), as docs/recording-format.md's table says."""
    rows = _table(_section(FORMAT, "Topics"))
    found: dict[str, tuple[str, str]] = {}
    for topic_cell, encoding, schema, *_ in rows:
        (topic,) = _code(topic_cell)
        (schema_name,) = _code(schema)
        assert topic not in found, f"{topic} is in the table twice"
        found[topic] = (encoding, schema_name)
    return found


def _topics_in_code() -> set[str]:
    """Every topic the code defines: uavtool.recording.topics, plus the MAVLink channels the
    writer owns and the channels `replay --vision` adds."""
    names = {
        value
        for name, value in vars(topics).items()
        if name.isupper() and isinstance(value, str) and value.startswith("/")
    }
    mavlink = {MAVLINK_RAW, mavlink_topic(Direction.IN, MSG), mavlink_topic(Direction.OUT, MSG)}
    return names | mavlink | {annotations.ANNOTATIONS, annotations.DETECTIONS}


def test_every_topic_in_the_code_is_documented_and_no_other() -> None:
    documented, defined = set(_documented_topics()), _topics_in_code()
    assert defined - documented == set(), "topics missing from docs/recording-format.md"
    assert documented - defined == set(), "documented topics the code does not define"


def _channels(path: Path) -> Iterator[tuple[str, str, str]]:
    """(topic, encoding, schema name) of every channel of a recording; MAVLink message names
    replaced by ``<MSG>``, as the table writes them."""
    with RecordingReader(path) as reader:
        schemas = {s.id: s.name for s in reader.schemas.values()}
        for channel in reader.channels.values():
            topic, schema = channel.topic, schemas.get(channel.schema_id, "")
            if re.fullmatch(r"/mavlink/(in|out)/[A-Z0-9_]+", topic):
                name = topic.rsplit("/", 1)[1]
                topic = topic.replace(name, MSG)
                schema = schema.replace(name, MSG)
            yield topic, channel.message_encoding, schema


def _assert_documented_as_written(paths: list[Path]) -> set[str]:
    documented = _documented_topics()
    seen = set()
    for path in paths:
        for written, encoding, schema in _channels(path):
            # a fleet's vehicle K writes the table's topics under /uavK (its own section)
            _, topic = split_topic(written)
            assert topic in documented, f"{path.name}: {written} is not documented"
            assert documented[topic] == (encoding, schema), f"{path.name}: {written}"
            seen.add(topic)
    return seen


def test_the_encodings_and_schemas_of_a_flight_are_as_documented() -> None:
    assert GOLDEN
    seen = _assert_documented_as_written(GOLDEN)
    assert {topics.OBSERVATIONS, topics.OUTPUTS, topics.SCENE, MAVLINK_RAW} <= seen


def test_the_encodings_and_schemas_of_record_and_replay_vision_are_as_documented(
    tmp_path: Path,
) -> None:
    """The channels `uavtool record` opens before its first message, and those
    `replay --vision` adds to a copy of a flight."""
    recorded = tmp_path / "record.mcap"
    with RecordingWriter(recorded, fsync=False) as writer:
        PassiveRecorder(writer, clock_ns=lambda: 1, origin=GeoPoint(50.0, 19.9, 200.0))
    detected = tmp_path / "vision.mcap"
    copy_with_detections(GOLDEN[0], detected, [], {"function": "m:f", "source": "paper.mcap"})
    seen = _assert_documented_as_written([recorded, detected])
    assert {topics.TELEMETRY, topics.FRAMES, annotations.ANNOTATIONS} <= seen


# --- the README's command table and the exit codes ----------------------------------------


def test_the_readme_command_table_is_the_cli() -> None:
    rows = _table(_section(README, "Commands"))
    listed = [_code(row[0])[0].split() for row in rows]
    assert all(words[0] == "uavtool" and len(words) == 2 for words in listed), listed
    assert sorted(words[1] for words in listed) == sorted(cli.commands)


@pytest.mark.parametrize("page", [README, DOCS / "fly.md"], ids=["README.md", "docs/fly.md"])
def test_the_exit_code_tables_are_flys(page: Path) -> None:
    codes: dict[str, int] = {}
    for status_cell, exit_cell, *_ in _table(_section(page, "How a flight ends")):
        for status in _code(status_cell):
            codes[status] = int(exit_cell)
    assert {s: c for s, c in codes.items() if s in EXIT_CODES} == EXIT_CODES
    assert codes.get("failed") == 1  # the runner's own status: the mission's code raised


# --- every command line in the documentation ----------------------------------------------


def _command_lines(path: Path) -> Iterator[str]:
    """The ``uavtool …`` command lines of a page: in its shell code blocks, and in its code
    spans (prose and tables)."""
    text = path.read_text(encoding="utf-8")
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            parts: list[list[str]] = [[]]
            for word in words:  # split at the shell's separators
                if word in ("&&", "||", "|", ";", "&"):
                    parts.append([])
                else:
                    parts[-1].append(word)
            for part in parts:
                if part[:1] == ["uavtool"]:
                    yield shlex.join(part)
    for span in re.findall(r"`(uavtool [^`]+)`", re.sub(r"```.*?```", "", text, flags=re.S)):
        yield " ".join(span.split())  # a span may break across lines


def _check(line: str) -> None:
    """The command path exists, and every option given belongs to the command."""
    words = shlex.split(line)[1:]
    command: click.Command = cli
    path = ["uavtool"]
    options = {"-h", "--help", *(o for p in cli.params for o in (*p.opts, *p.secondary_opts))}
    while words and isinstance(command, click.Group) and not words[0].startswith("-"):
        word = words.pop(0)
        if word.isupper() or word in ("…", "..."):  # a placeholder: `uavtool COMMAND --help`
            return
        assert word in command.commands, f"`{line}`: {' '.join(path)} has no command {word!r}"
        command = command.commands[word]
        path.append(word)
    options |= {o for p in command.params for o in (*p.opts, *p.secondary_opts)}
    for word in words:
        if re.fullmatch(r"--?[A-Za-z][-A-Za-z]*(=.*)?", word):
            name = word.split("=", 1)[0]
            assert name in options, f"`{line}`: {' '.join(path)} has no option {name}"


LINES = sorted({(p.relative_to(ROOT).as_posix(), ln) for p in PAGES for ln in _command_lines(p)})


@pytest.mark.parametrize(("page", "line"), LINES, ids=[f"{p}: {ln}" for p, ln in LINES])
def test_every_documented_command_line_exists(page: str, line: str) -> None:
    _check(line)


def test_the_pages_name_many_command_lines() -> None:
    """The parsing above finds what it should (it is not silently empty)."""
    assert len(LINES) > 100
    assert any(ln.startswith("uavtool sweep ") for _, ln in LINES)


# --- links ----------------------------------------------------------------------------------


def _anchors(path: Path) -> set[str]:
    """GitHub's anchors for a page's headings."""
    text = re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S)
    found = set()
    for heading in re.findall(r"^#+ (.+)$", text, re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")
        found.add(slug)
    return found


@pytest.mark.parametrize("page", PAGES, ids=[p.relative_to(ROOT).as_posix() for p in PAGES])
def test_every_relative_link_resolves(page: Path) -> None:
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue  # a web address
        file, _, anchor = target.partition("#")
        linked = (page.parent / file).resolve() if file else page
        assert linked.exists(), f"{page.name}: link to {target}: no such file"
        if anchor:
            assert anchor in _anchors(linked), f"{page.name}: link to {target}: no such heading"


# --- the mission example ----------------------------------------------------------------------


def test_the_mission_example_in_docs_missions_flies_and_replays(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/missions.md's HopMission, pasted into my_missions/hop.py as the page says."""
    page = (DOCS / "missions.md").read_text(encoding="utf-8")
    (code,) = [b for b in re.findall(r"```python\n(.*?)```", page, re.S) if "HopMission" in b]
    assert code.startswith("# my_missions/hop.py\n")
    (tmp_path / "my_missions").mkdir()
    (tmp_path / "my_missions" / "hop.py").write_text(textwrap.dedent(code))
    monkeypatch.syspath_prepend(str(tmp_path))
    rec = tmp_path / "hop.mcap"
    mission = "my_missions.hop:HopMission"
    result = CliRunner().invoke(
        cli, ["fly", "-q", "--mission", mission, "--set", "hop.photos=2", "-o", str(rec)]
    )
    assert result.exit_code == 0, result.output
    assert "completed: 2 photos" in result.output
    result = CliRunner().invoke(cli, ["replay", "--check", str(rec), "--mission", mission])
    assert result.exit_code == 0, result.output


def test_the_fleet_mission_example_in_docs_fleets_flies_and_replays(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/fleets.md's SpreadMission, pasted into my_missions/spread.py as the page says."""
    page = (DOCS / "fleets.md").read_text(encoding="utf-8")
    (code,) = [b for b in re.findall(r"```python\n(.*?)```", page, re.S) if "SpreadMission" in b]
    assert code.startswith("# my_missions/spread.py\n")
    (tmp_path / "my_missions").mkdir()
    (tmp_path / "my_missions" / "spread.py").write_text(textwrap.dedent(code))
    monkeypatch.syspath_prepend(str(tmp_path))
    rec = tmp_path / "spread.mcap"
    mission = "my_missions.spread:SpreadMission"
    args = ["fly", "-q", "--vehicles", "3", "--mission", mission, "-o", str(rec)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "completed: every vehicle completed" in result.output
    assert "(kept: 5 m)" in result.output
    result = CliRunner().invoke(cli, ["replay", "--check", str(rec), "--mission", mission])
    assert result.exit_code == 0, result.output
    assert "identical: every output of every vehicle" in result.output
