"""Writing to a named pipe: only while someone reads it.

Opening a named pipe for writing blocks until a reader opens it, so ``-o PIPE`` with nobody
at the other end hung a command for ever. :func:`reader_held` checks for a reader without
blocking, and keeps its own end open while the command writes, so that the reader does not
see the end of the stream between the check and the command's own open.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from uavtool.errors import InputError


@contextmanager
def reader_held(path: str | Path) -> Iterator[None]:
    """Around writing ``path``: nothing unless it is a named pipe; then InputError at once
    when nobody reads it (writing would block for ever)."""
    try:
        is_fifo = stat.S_ISFIFO(Path(path).stat().st_mode)
    except OSError:
        is_fifo = False  # not there yet: a file will be created
    if not is_fifo:
        yield
        return
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
    except OSError as exc:
        if exc.errno != errno.ENXIO:
            raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from None
        raise InputError(
            f"{path}: a named pipe that nobody reads (writing would wait for ever): "
            "start its reader first, or write to a file"
        ) from None
    try:
        yield
    finally:
        os.close(fd)
