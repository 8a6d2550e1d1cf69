"""Issue 30, item 6: a sweep's bad addresses, sizes and files are one line and exit 2, before
anything is written or allocated; the local cluster's dashboard listens on this machine only
unless the user asks."""

from __future__ import annotations

import socket
import time
from pathlib import Path

import psutil
import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.errors import InputError
from uavtool.sweep.cluster import open_client

SPEC = '[scenes]\nbuiltin = ["paper"]\n[grid]\nseed = [0]\n'


def _sweep(tmp_path: Path, spec: str | bytes, *args: str) -> tuple[str, Path]:
    path = tmp_path / "spec.toml"
    if isinstance(spec, bytes):
        path.write_bytes(spec)
    else:
        path.write_text(spec)
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["sweep", str(path), "--output", str(out), "-q", *args])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1, result.output
    return result.output, out


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--scheduler", "not a url", "--scheduler 'not a url': expected HOST:PORT"),
        ("--scheduler", "tcp://[::1]:notaport", "'tcp://[::1]:notaport': expected HOST:PORT"),
        ("--scheduler", "tcp://head:99999", "with a port 0-65535, e.g. tcp://HOST:8786"),
        ("--dashboard", "everywhere", "--dashboard 'everywhere': expected HOST:PORT"),
    ],
)
def test_a_bad_address_is_one_line_and_leaves_no_output_folder(
    tmp_path: Path, option: str, value: str, message: str
) -> None:
    output, out = _sweep(tmp_path, SPEC, option, value)
    assert message in output
    assert not out.exists()  # no spec.toml left behind


def test_an_unreachable_scheduler_leaves_no_output_folder(tmp_path: Path) -> None:
    with socket.socket() as closed:  # a port nobody listens on
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
    t0 = time.perf_counter()
    output, out = _sweep(tmp_path, SPEC, "--scheduler", f"tcp://127.0.0.1:{port}")
    took = time.perf_counter() - t0
    assert f"cannot connect: nothing listens on 127.0.0.1:{port} (connection refused)" in output
    assert took < 5.0  # at once: Dask alone tries again for its whole 10 s timeout
    assert not out.exists()
    spec = tmp_path / "spec.toml"  # without -q: no progress bar before the one line
    result = CliRunner().invoke(
        cli,
        ["sweep", str(spec), "-o", str(tmp_path / "o2"), "--scheduler", f"tcp://127.0.0.1:{port}"],
    )
    assert result.exit_code == 2
    assert result.output.strip().splitlines() == [output.strip()], result.output


def test_an_enormous_grid_is_refused_before_planning_it(tmp_path: Path) -> None:
    grid = "".join(
        f"{key} = {{ from = 0, to = 999, step = 1 }}\n"
        for key in ("seed", "wind_speed_ms", "wind_from_deg")
    )
    t0 = time.perf_counter()
    output, out = _sweep(tmp_path, f'[scenes]\nbuiltin = ["paper"]\n[grid]\n{grid}')
    took = time.perf_counter() - t0
    assert "1,000,000,000 flights (1 scene x 1 case x 1000 seed values" in output
    assert "at most 100,000 in one sweep" in output
    assert took < 5.0  # it ran 26 s to a MemoryError at 3.5 GB
    assert not out.exists()


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("a = " + "[" * 5000 + "]" * 5000 + "\n", "not valid TOML: nested too deeply"),
        (bytes(range(256)) * 64, "not UTF-8 text (byte 128)"),
        (b"# " + b"x" * (3 << 20), "larger than 1024 KiB: not a sweep spec"),
    ],
)
def test_a_hostile_spec_file_is_one_line(tmp_path: Path, spec: str | bytes, message: str) -> None:
    output, _ = _sweep(tmp_path, spec)
    assert message in output


def test_a_scene_path_to_a_secret_file_does_not_echo_it(tmp_path: Path) -> None:
    shadow = tmp_path / "shadow"
    shadow.write_text("root:$6$Zx9SALT$SECRETHASHabc:20228:0:99999:7:::\n")
    output, _ = _sweep(tmp_path, f'[scenes]\nfiles = ["{shadow}"]\n')
    assert "scenes.files[0]" in output and "not a scene key" in output
    assert "SECRETHASH" not in output and "20228" not in output and "$6$" not in output


def _listening_hosts(port: int) -> set[str]:
    return {
        c.laddr.ip
        for c in psutil.Process().net_connections(kind="tcp")
        if c.status == psutil.CONN_LISTEN and c.laddr.port == port
    }


@pytest.mark.parametrize(
    ("dashboard", "hosts"), [(None, {"127.0.0.1"}), ("0.0.0.0:0", {"0.0.0.0"})]
)
def test_the_local_dashboard_listens_on_this_machine_unless_asked(
    dashboard: str | None, hosts: set[str]
) -> None:
    with open_client(workers=1, dashboard=dashboard) as client:
        port = client.cluster.scheduler.http_server.port  # type: ignore[union-attr]
        assert _listening_hosts(port) == hosts


def test_dashboard_and_workers_are_the_local_clusters() -> None:
    with pytest.raises(InputError, match="--dashboard is the local cluster's"):  # noqa: SIM117
        with open_client("tcp://127.0.0.1:8786", dashboard="127.0.0.1:8787"):
            pass
