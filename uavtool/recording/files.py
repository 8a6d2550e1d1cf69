"""Files in and out, safely: an input must be a regular file (a named pipe would hang the
reader), an output must not be one of the inputs, and an output appears only once it is
complete.

`atomic_output` writes to a temporary file beside the output and renames it over the output
only on success; on failure the temporary file is removed, so a failed command leaves
nothing behind and never half-overwrites what was there. An output that exists and is not a
regular file (``/dev/null``, ``/dev/full``, a pipe) is written in place: renaming over it
would replace the device.
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

from uavtool.errors import InputError
from uavtool.fifo import reader_held


class SameFileError(InputError):
    """An output names (directly, by a symbolic or a hard link) one of the inputs."""


class NotRegularFileError(InputError):
    """An input is a directory, a named pipe, a device or a socket."""


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def open_input(path: str | Path) -> BinaryIO:
    """Open ``path`` for reading without blocking on a named pipe; raises
    `NotRegularFileError` unless it is a regular file, `OSError` if it cannot be opened."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise NotRegularFileError(f"{path}: {_kind(mode)}, not a recording file")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def refuse_same_file(output: str | Path, inputs: Iterable[str | Path | None]) -> None:
    """Raise `SameFileError` if ``output`` exists and is the same file (device and inode,
    through any link) as one of ``inputs``."""
    try:
        out = Path(output).stat()
    except OSError:
        return  # does not exist (yet): it cannot be an input
    for source in inputs:
        if source is None:
            continue
        try:
            src = Path(source).stat()
        except OSError:
            continue
        if (src.st_dev, src.st_ino) == (out.st_dev, out.st_ino):
            raise SameFileError(
                f"{output}: this is the input {source}; writing it would destroy it: "
                "choose another output file"
            )


def _in_place(path: Path) -> bool:
    try:
        return not stat.S_ISREG(path.stat().st_mode)
    except OSError:
        return False


def temporary_path(output: Path) -> Path:
    """Where `atomic_output` writes ``output`` until it is complete (same folder)."""
    return output.with_name(f"{output.name}.{os.getpid()}.partial")


@contextmanager
def atomic_output(
    output: str | Path,
    *,
    inputs: Iterable[str | Path | None] = (),
    keep_on_error: Callable[[BaseException], bool] | None = None,
) -> Iterator[Path]:
    """Yield the path to write ``output`` to; on leaving without an exception it becomes
    ``output`` (a symbolic link keeps pointing at it), on an exception it is removed unless
    ``keep_on_error`` says the partial file is worth keeping (a flight that did happen).
    Raises `SameFileError` at once if ``output`` is one of ``inputs``."""
    output = Path(output)
    refuse_same_file(output, inputs)
    if _in_place(output):
        with reader_held(output):
            yield output
        return
    final = output.resolve() if output.is_symlink() else output
    tmp = temporary_path(final)
    try:
        yield tmp
    except BaseException as exc:
        if keep_on_error is not None and keep_on_error(exc) and tmp.exists():
            with contextlib.suppress(OSError):
                tmp.replace(final)
                sync_folder(final.parent)
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    try:
        tmp.replace(final)
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise InputError(f"{output}: cannot write: {exc.strerror or exc}") from None
    sync_folder(final.parent)


def sync_folder(folder: Path) -> None:
    """Put a rename in ``folder`` on disk (fsync of the folder itself: without it a power cut
    soon after can bring back the old name). Best effort: a file system that cannot sync a
    folder (some network ones, Windows) loses nothing more than it did before."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
