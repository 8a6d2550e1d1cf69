"""Errors of the viewer: a recording it cannot show, a viewer it cannot start."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from uavtool.errors import InputError
from uavtool.recording import Entry
from uavtool.terminal import safe_text


class ViewError(InputError):
    """A recording holds no mission to show, or the viewer cannot be served as asked."""


class PortInUseError(ViewError):
    """A port the web viewer's servers are to listen on is taken."""


class ContentError(ViewError):
    """A recorded message holds a value of a type or range the viewer cannot show."""


@contextmanager
def showing(path: str | Path, entry: Entry) -> Iterator[None]:
    """Show ``entry`` of ``path``: a recorded value of the wrong type or range (a frame index
    of infinity, a string for a number, a missing field) is one line naming the message, not
    a traceback. The recording's content is untrusted input, like its bytes."""
    try:
        yield
    except (ValueError, TypeError, KeyError, IndexError, OverflowError, AttributeError) as exc:
        what = safe_text(f"{type(exc).__name__}: {exc}")
        what = what if len(what) <= 80 else what[:77] + "..."
        raise ContentError(
            f"{path}: topic {entry.topic!r} #{entry.sequence}: a value the viewer cannot show "
            f"({what}); the file was not written by uavtool as it is, or was altered"
        ) from None
    except RecursionError:
        raise ContentError(
            f"{path}: topic {entry.topic!r} #{entry.sequence}: a value nested too deep to show"
        ) from None
