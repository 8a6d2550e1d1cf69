"""A TCP vehicle that refuses is tried again for --timeout (ArduPilot's SITL may still be
starting), and the user is told so at once, not only when the time is up."""

from __future__ import annotations

import socket

from click.testing import CliRunner

from uavtool.cli import cli


def test_a_refused_connection_says_so_at_once_then_gives_up(tmp_path: object) -> None:
    with socket.socket() as closed:  # a port nobody listens on
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
    result = CliRunner().invoke(
        cli, ["fly", "--connect", f"tcp:127.0.0.1:{port}", "--no-record", "--timeout", "1"]
    )
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert lines[0] == (
        f"uavtool fly: tcp:127.0.0.1:{port}: Connection refused; trying again for up to 1 s "
        "(is the vehicle running? Ctrl-C stops)"
    )
    assert lines[-1] == f"uavtool: error: tcp:127.0.0.1:{port}: cannot connect: Connection refused"
    assert len(lines) == 2
