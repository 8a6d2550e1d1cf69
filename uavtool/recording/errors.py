"""Errors raised when a recording (or a tlog) cannot be read or written as asked.

Every one is an `InputError` (exit code 2): the user pointed us at a file we cannot use.
Messages start with the file name and say what is wrong with it.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import BinaryIO

from uavtool.errors import InputError


class RecordingError(InputError):
    """Root of the recording errors: ``<file>: <what is wrong>``."""

    def __init__(self, path: str | Path, problem: str) -> None:
        super().__init__(f"{path}: {problem}")
        self.path = str(path)
        self.problem = problem


class NotMcapError(RecordingError):
    """The file is empty, missing, or does not start with the MCAP magic."""


class TopicNotFoundError(RecordingError):
    """A topic that was asked for is not in the recording."""

    def __init__(self, path: str | Path, topic: str, available: list[str]) -> None:
        listing = ", ".join(available) if available else "none"
        super().__init__(path, f"no topic {topic!r} (topics: {listing})")
        self.topic = topic


class UnknownSchemaError(RecordingError):
    """A channel's schema or encoding is not one this reader decodes."""


class CorruptRecordingError(RecordingError):
    """Part of the recording fails its checks (a chunk's CRC, a record that does not parse)
    and what was asked for cannot be read whole."""


class TlogError(RecordingError):
    """A telemetry log (.tlog) holds no MAVLink frames we can read."""


def create_file(path: str | Path) -> BinaryIO:
    """Open ``path`` for writing; a `RecordingError` naming it if the OS refuses (the file
    the user asked for, when ``path`` is its temporary ``NAME.PID.partial``)."""
    try:
        return Path(path).open("wb")
    except OSError as exc:
        asked = re.sub(r"\.\d+\.partial$", "", str(path))
        raise RecordingError(asked, f"cannot create: {exc.strerror}") from exc


def write_failed(path: str | Path, exc: OSError) -> RecordingError:
    """The error for a write to ``path`` that the OS refused (a full disk …)."""
    return RecordingError(path, f"cannot write: {exc.strerror or exc}")
