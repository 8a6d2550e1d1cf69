"""Scene file text (YAML, TOML or JSON) to plain data, within :mod:`uavtool.world.limits`.

YAML is read in two passes. The first walks the parser's events, which costs nothing per
alias use: it refuses nesting deeper than ``MAX_DEPTH``, values longer than
``MAX_TEXT_CHARS``, and more than ``MAX_NODES`` values once every alias is expanded (a
"billion laughs" file is refused after reading its few hundred bytes), and aliases to a node
that encloses them. Only then is the document composed, its line numbers recorded for error
messages and duplicate keys refused. JSON and TOML parsers build plain data directly; their
duplicate keys are refused too, and their nesting depth is checked on the result.
"""

from __future__ import annotations

import json
import tomllib
from typing import Any

import yaml

from uavtool.world.errors import SceneError
from uavtool.world.limits import MAX_DEPTH, MAX_FILE_BYTES, MAX_NODES, MAX_TEXT_CHARS

# libyaml's parser when installed: ~15× faster than PyYAML's own, same events and marks.
_LOADER: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

KeyPath = tuple[str | int, ...]
LineMap = dict[KeyPath, int]


def parse_text(text: str, *, source: str, suffix: str) -> tuple[object, LineMap]:
    """The plain data a scene file holds, and the line of each key path (YAML only).

    ``suffix`` (.yaml/.yml/.toml/.json) picks the syntax. Raises SceneError.
    """
    if len(text) > MAX_FILE_BYTES or len(text.encode("utf-8")) > MAX_FILE_BYTES:
        raise SceneError(f"{source}: larger than {MAX_FILE_BYTES >> 10} KiB, not a scene")
    lines: LineMap = {}
    if suffix == ".toml":
        data = _load_toml(text, source)
    elif suffix == ".json":
        data = _load_json(text, source)
    else:
        return _load_yaml(text, source, lines), lines
    _check_plain_depth(data, source)
    return data, lines


# --------------------------------------------------------------------------- YAML


def _load_yaml(text: str, source: str, lines: LineMap) -> object:
    loader = _LOADER(text)
    try:
        _scan_events(text, source)
        node = loader.get_single_node()
        if node is None:
            raise SceneError(f"{source}: empty scene file")
        _record_lines(node, (), lines, source)
        return loader.construct_document(node)
    except yaml.MarkedYAMLError as exc:
        line = exc.problem_mark.line + 1 if exc.problem_mark is not None else "?"
        raise SceneError(f"{source}:{line}: invalid YAML: {exc.problem}") from None
    except yaml.YAMLError as exc:
        raise SceneError(f"{source}: invalid YAML: {_one_line(exc)}") from None
    except (ValueError, OverflowError) as exc:  # e.g. a timestamp with month 13
        raise SceneError(f"{source}: invalid YAML value: {_one_line(exc)}") from None
    finally:
        loader.dispose()


def _scan_events(text: str, source: str) -> None:
    """Refuse deep nesting, long values, alias bombs and self-enclosing aliases."""
    expanded: dict[str, int] = {}  # anchor → values it stands for
    anchors: list[str | None] = []  # per open collection
    counts = [0]  # values so far: the stream's, then one per open collection
    for event in yaml.parse(text, Loader=_LOADER):
        line = event.start_mark.line + 1 if event.start_mark is not None else "?"
        if isinstance(event, yaml.CollectionStartEvent):
            if len(anchors) >= MAX_DEPTH:
                raise SceneError(f"{source}:{line}: nested deeper than {MAX_DEPTH} levels")
            anchors.append(event.anchor)
            counts.append(1)
            continue
        if isinstance(event, yaml.CollectionEndEvent):
            anchor = anchors.pop()
            size = counts.pop()
            if anchor is not None:
                expanded[anchor] = size
        elif isinstance(event, yaml.ScalarEvent):
            if len(event.value) > MAX_TEXT_CHARS:
                raise SceneError(
                    f"{source}:{line}: a value longer than {MAX_TEXT_CHARS} characters"
                )
            size = 1
            if event.anchor is not None:
                expanded[event.anchor] = 1
        elif isinstance(event, yaml.AliasEvent):
            if event.anchor not in expanded:
                raise SceneError(
                    f"{source}:{line}: alias *{event.anchor} is undefined or inside its own anchor"
                )
            size = expanded[event.anchor]
        else:  # stream and document boundaries
            continue
        counts[-1] += size
        if counts[-1] > MAX_NODES:
            raise SceneError(
                f"{source}:{line}: more than {MAX_NODES} values with aliases expanded "
                "(an alias bomb?)"
            )


def _record_lines(node: yaml.Node, path: KeyPath, lines: LineMap, source: str) -> None:
    """Line of every key path; refuses duplicate and non-scalar keys. The event scan has
    bounded depth and size (aliases included), so this walk is bounded too."""
    lines[path] = node.start_mark.line + 1
    if isinstance(node, yaml.MappingNode):
        seen: dict[str, int] = {}
        for key_node, value_node in node.value:
            line = key_node.start_mark.line + 1
            if not isinstance(key_node, yaml.ScalarNode):
                raise SceneError(f"{source}:{line}: {_where(path)}keys must be plain text")
            key = str(key_node.value)
            if key in seen and key != "<<":
                raise SceneError(
                    f"{source}:{line}: {_where(path)}duplicate key {key!r} "
                    f"(first on line {seen[key]})"
                )
            seen[key] = line
            lines[(*path, key)] = line
            _record_lines(value_node, (*path, key), lines, source)
            lines[(*path, key)] = line
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _record_lines(item, (*path, i), lines, source)


# --------------------------------------------------------------------------- JSON, TOML


class _DuplicateKeyError(Exception):
    pass


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKeyError(key)
        out[key] = value
    return out


def _load_json(text: str, source: str) -> object:
    try:
        return json.loads(text, object_pairs_hook=_no_duplicates)
    except json.JSONDecodeError as exc:
        raise SceneError(f"{source}:{exc.lineno}: invalid JSON: {exc.msg}") from None
    except _DuplicateKeyError as exc:
        raise SceneError(f"{source}: duplicate key {exc.args[0]!r}") from None
    except RecursionError:
        raise SceneError(f"{source}: nested deeper than {MAX_DEPTH} levels") from None
    except ValueError:  # an integer of more than 4300 digits
        raise SceneError(f"{source}: invalid JSON: a number too long to read") from None


def _load_toml(text: str, source: str) -> object:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: invalid TOML: {_one_line(exc)}") from None
    except RecursionError:
        raise SceneError(f"{source}: nested deeper than {MAX_DEPTH} levels") from None
    except ValueError:  # an integer of more than 4300 digits
        raise SceneError(f"{source}: invalid TOML: a number too long to read") from None


def _check_plain_depth(data: object, source: str) -> None:
    """Depth and size of parsed data, walked without recursion."""
    stack: list[tuple[object, int, KeyPath]] = [(data, 0, ())]
    count = 0
    while stack:
        value, depth, path = stack.pop()
        count += 1
        if count > MAX_NODES:
            raise SceneError(f"{source}: more than {MAX_NODES} values")
        if isinstance(value, dict | list):
            if depth >= MAX_DEPTH:
                raise SceneError(f"{source}: {_where(path)}nested deeper than {MAX_DEPTH} levels")
            items = value.items() if isinstance(value, dict) else enumerate(value)
            stack.extend((v, depth + 1, (*path, k)) for k, v in items)
        elif isinstance(value, str) and len(value) > MAX_TEXT_CHARS:
            raise SceneError(
                f"{source}: {_where(path)}a value longer than {MAX_TEXT_CHARS} characters"
            )


# --------------------------------------------------------------------------- messages


def format_path(path: KeyPath) -> str:
    """``("buildings", 2, "name")`` → ``buildings[2].name``; odd keys shown quoted."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
            continue
        name = part if part.isidentifier() else _clip(repr(part))
        out += f".{name}" if out else name
    return out


def _where(path: KeyPath) -> str:
    return f"{format_path(path)}: " if path else ""


def _clip(text: str, limit: int = 40) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())
