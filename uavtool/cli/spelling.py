"""Old option spellings that keep working for one release, each with one warning line.

Every command names what it writes ``-o/--output``, its mission parameters ``--set``
(``--set-file`` for a JSON file of them) and its durations in SECONDS. The spellings used
before (``--out``, sweep's ``-o KEY=VALUE`` and ``--override``, replay's ``--params``, fly's
``--record``, view's ``--port``) are rewritten to the new ones before click parses the
command line: help lists only the new names, and a bad value is reported under them.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import click


def _always(_value: str) -> bool:
    return True


@dataclass(frozen=True, slots=True)
class OldSpelling:
    """``old`` (e.g. ``--out``) now spelled ``new`` (a long option, e.g. ``--output``)."""

    old: str
    new: str
    advice: str
    """What the warning says to use instead, e.g. ``-o/--output``."""
    applies: Callable[[str], bool] = _always
    """Whether the old spelling is meant, given its value (sweep's ``-o`` is both)."""
    described: str = ""
    """How the warning names the old spelling; empty: ``old``."""

    def warning(self) -> str:
        return (
            f"uavtool: warning: {self.described or self.old} is deprecated and goes in the "
            f"next release; use {self.advice}"
        )


_SETTING = re.compile(r"\s*[A-Za-z_][\w-]*(\.[\w-]+)+\s*=")


def looks_like_setting(value: str) -> bool:
    """``KEY.PATH=VALUE`` (``random.draws=50``), as opposed to a path (``sweeps/wind``)."""
    return _SETTING.match(value) is not None


class Command(click.Command):
    """A command that still takes its ``old_spellings``: each is rewritten to its new
    spelling, and the first use of each prints its warning on stderr."""

    def __init__(self, *args: Any, old_spellings: Sequence[OldSpelling] = (), **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.old_spellings = tuple(old_spellings)

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        if self.old_spellings:
            args, used = modernise(args, self.old_spellings, self._options(ctx))
            if not ctx.resilient_parsing:
                for spelling in used:
                    click.echo(spelling.warning(), err=True)
        return super().parse_args(ctx, args)

    def _options(self, ctx: click.Context) -> dict[str, bool]:
        return {
            opt: not (param.is_flag or param.count)
            for param in self.get_params(ctx)
            if isinstance(param, click.Option)
            for opt in param.opts
        }


def modernise(
    args: Sequence[str], old_spellings: Sequence[OldSpelling], options: Mapping[str, bool]
) -> tuple[list[str], list[OldSpelling]]:
    """``args`` with every old spelling replaced by its new one, and the old spellings used
    (each once, in order of first use). Option values and everything after ``--`` are kept
    as they are; ``options`` maps each option the command has (``-o``, ``--output``) to
    whether it takes a value."""
    old = {s.old: s for s in old_spellings}
    out: list[str] = []
    used: list[OldSpelling] = []
    todo = deque(args)
    while todo:
        token = todo.popleft()
        if token == "--":
            out += [token, *todo]
            break
        if not token.startswith("-") or token == "-":
            out.append(token)
            continue
        name, attached = _name_and_value(token)
        spelling = old.get(name)
        short = not token.startswith("--")
        if short and spelling is None and attached is not None and options.get(name) is False:
            out.append(name)  # short flags written together: -qo x is -q -o x
            todo.appendleft("-" + attached)
            continue
        consumes = attached is None and (
            options.get(name, False) or (spelling is not None and options[spelling.new])
        )
        value = todo.popleft() if consumes and todo else attached
        if spelling is not None and spelling.applies(value or ""):
            if spelling not in used:
                used.append(spelling)
            token = spelling.new if attached is None else f"{spelling.new}={attached}"
        out.append(token)
        if consumes and value is not None:
            out.append(value)
    return out, used


def _name_and_value(token: str) -> tuple[str, str | None]:
    """``--out=x`` → (``--out``, ``x``); ``-ox`` → (``-o``, ``x``); ``-o`` → (``-o``, None)."""
    if token.startswith("--"):
        name, eq, value = token.partition("=")
        return name, value if eq else None
    return token[:2], token[2:] or None
