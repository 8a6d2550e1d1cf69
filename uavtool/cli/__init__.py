"""The ``uavtool`` command line: parse, call one library function, map errors to exit codes.

Each command group lives in its own module here and is registered in ``_COMMANDS``; the
library below never imports click and never prints.
"""

from __future__ import annotations

import gc
import importlib
import logging
import os
import sys
from typing import Any

import click
from click.exceptions import NoArgsIsHelpError

from uavtool import __version__
from uavtool.errors import UavtoolError

# (module, attribute) of every top-level command, in the order `--help` lists them.
_COMMANDS: tuple[tuple[str, str], ...] = (
    ("uavtool.cli.fly", "fly"),
    ("uavtool.cli.missions", "missions"),
    ("uavtool.cli.replay", "replay"),
    ("uavtool.cli.record", "record"),
    ("uavtool.cli.sitl", "sitl"),
    ("uavtool.cli.recording", "info"),
    ("uavtool.cli.recording", "export"),
    ("uavtool.cli.recording", "import_"),
    ("uavtool.cli.scene", "scene"),
    ("uavtool.cli.vision", "vision"),
    ("uavtool.cli.view", "view"),
    ("uavtool.cli.sweep", "sweep"),
)


class _Group(click.Group):
    """Turns library errors into one-line messages and exit codes (2 input, 1 failure)."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except UavtoolError as exc:
            if ctx.obj and ctx.obj.get("debug"):
                raise
            click.echo(f"uavtool: error: {exc}", err=True)
            ctx.exit(exc.exit_code)
        except KeyboardInterrupt:
            click.echo("uavtool: interrupted", err=True)
            ctx.exit(130)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="uavtool")
@click.option("--debug", is_flag=True, help="Show tracebacks instead of one-line errors.")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
@click.pass_context
def cli(ctx: click.Context, debug: bool, verbose: int) -> None:
    """Fly, record, replay and view vision missions for MAVLink drones."""
    ctx.ensure_object(dict)
    ctx.obj["debug"] = debug
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")


def _first_sentence(command: click.Command) -> str:
    """A command's first sentence, whole: click would cut it at the terminal's width."""
    text = " ".join((command.help or "").split("\n\n", 1)[0].split())
    end = text.find(". ")
    return text if end < 0 else text[: end + 1]


def _whole_help_lines(command: click.Command) -> None:
    if command.short_help is None:
        command.short_help = _first_sentence(command)
    if isinstance(command, click.Group):
        for sub in command.commands.values():
            _whole_help_lines(sub)


for _module, _attr in _COMMANDS:
    cli.add_command(getattr(importlib.import_module(_module), _attr))
_whole_help_lines(cli)


def main() -> None:
    """Console-script entry point. A command line click cannot parse (an unknown option, a
    bad value, a missing argument) is one line on stderr, exit 2, like every other error."""
    _one_blas_thread()
    try:
        _main()
    finally:
        # The command is done; the interpreter's teardown is left, and its last garbage
        # collection walks every object numpy, OpenCV, trimesh … made: 60-90 ms of a fly or
        # replay. Frozen objects are skipped by it (files are closed, atexit still runs).
        gc.freeze()


def _one_blas_thread() -> None:
    """A command flies one flight (or reads one recording) on one thread, and numpy's
    OpenBLAS worker threads only spin-wait after each of its small matrix products: ~0.3 s of
    CPU in a 1.2 s ``uavtool fly``, taken from the core a recording's writer process or a
    sweep's other workers use. Set before numpy loads (none of the commands' modules imports
    it); a user's own ``OPENBLAS_NUM_THREADS`` wins. One thread computes the same products,
    bit for bit: each output element is one thread's dot product either way."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _main() -> None:
    try:
        code = cli.main(prog_name="uavtool", standalone_mode=False)
    except NoArgsIsHelpError as exc:  # a bare group: its help, as click shows it
        click.echo(exc.format_message(), err=True)
        sys.exit(exc.exit_code)
    except click.UsageError as exc:
        where = exc.ctx.command_path if exc.ctx is not None else "uavtool"
        click.echo(f"uavtool: error: {exc.format_message()} (see '{where} --help')", err=True)
        sys.exit(exc.exit_code)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.Abort:
        click.echo("Aborted!", err=True)
        sys.exit(1)
    sys.exit(code if isinstance(code, int) else 0)  # an exit code from ctx.exit, --help
