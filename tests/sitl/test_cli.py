"""``uavtool sitl`` from the shell, driven by pymavlink's own mavutil as a user would."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_help_has_an_example() -> None:
    result = CliRunner().invoke(cli, ["sitl", "--help"])
    assert result.exit_code == 0
    assert "Example" in result.output and "--speedup" in result.output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--endpoint", "bogus"], "endpoint 'bogus'"),
        (["--home", "1,2"], "--home '1,2'"),
        (["--signing-key", "abc"], "--signing-key"),
        (["--params", "/nonexistent.parm"], "/nonexistent.parm: cannot read"),
        (["--speedup", "0"], "speedup must be > 0"),
        (["--wind", "x,y"], "--wind 'x,y'"),
        (["--wind", "1e300,0"], "speed must be 0..50 m/s"),
        (["--wind", "5,nan"], "direction must be finite"),
        (["--duration", "-1"], "--duration -1"),
        (["--duration", "nan"], "--duration nan"),
        (["--home", "0,0,1e308,0"], "altitude must be"),
        (["--home", "0,0,0,inf"], "heading must be finite"),
        (["--speedup", "1e-30"], "SIM_SPEEDUP: 1e-30 out of range"),
        (["--speedup", "inf"], "SIM_SPEEDUP"),
        (["--param", "SIM_GPS_NOISE=1e30"], "SIM_GPS_NOISE: 1e+30 out of range 0..100"),
        (["--param", "LAND_SPEED=-32768"], "LAND_SPEED: -32768 out of range 30..200"),
        (["--param", "SIM_BATT_VOLTAGE=-3.4e38"], "SIM_BATT_VOLTAGE"),
        (["--param", "NOPE=1"], "unknown parameter 'NOPE'"),
        (["--param", "RTL_ALT"], "expected NAME=VALUE"),
        (["--link-outage", "5:inf"], "link outage 5:inf"),
        (["--vehicles", "2", "--offset-line", "90"], "offset line '90'"),
        (["--vehicles", "3", "--home", "1,2,3,4", "--home", "1,2,3,5"], "--home given 2 times"),
        (["--vehicles", "2", "--scene", "paper", "--offset-line", "0,10"], "in building 'purple'"),
    ],
)
def test_bad_options_exit_2_with_one_line(args: list[str], message: str) -> None:
    result = CliRunner().invoke(cli, ["sitl", *args])
    assert result.exit_code == 2
    assert message in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_shell_session_with_mavutil() -> None:
    port = _free_port()
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "uavtool",
            "sitl",
            "--speedup",
            "5",
            "--endpoint",
            f"tcpin:127.0.0.1:{port}",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    try:
        assert proc.stdout is not None
        banner = proc.stdout.readline() + proc.stdout.readline()
        assert f"tcpin:127.0.0.1:{port}" in banner
        script = f"""
import os
os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil
m = mavutil.mavlink_connection("tcp:127.0.0.1:{port}", source_system=255)
m.wait_heartbeat(timeout=10)
m.set_mode("GUIDED")
while not m.motors_armed():  # like ArduCopter, it refuses to arm for a few s after boot
    m.arducopter_arm()
    m.recv_match(type="HEARTBEAT", blocking=True, timeout=1)
m.mav.command_long_send(1, 1, mavutil.mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 0, 5)
while m.recv_match(type="GLOBAL_POSITION_INT", blocking=True, timeout=10).relative_alt < 4800:
    pass
m.set_mode("LAND")
m.motors_disarmed_wait()
print("landed", m.recv_match(type="GLOBAL_POSITION_INT", blocking=True).relative_alt)
"""
        out = subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False
        )
        assert out.returncode == 0, out.stderr
        assert out.stdout.startswith("landed")
        assert abs(int(out.stdout.split()[1])) < 100
    finally:
        proc.terminate()
        proc.communicate(timeout=10)


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_stop_signal_stops_cleanly_with_its_exit_code(sig: signal.Signals, code: int) -> None:
    """As every other command (and shell): 128 + the signal, after the clean stop."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "uavtool", "sitl", "--endpoint", "tcpin:127.0.0.1:0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None and proc.stderr is not None
    for line in proc.stdout:  # until it serves (not for ever if it ended first)
        if "Ctrl-C to stop" in line:
            break
    else:
        pytest.fail(f"uavtool sitl ended before serving ({proc.wait()}): {proc.stderr.read()}")
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == code, err
    assert "uavtool sitl: stopped at sim time" in out and "Traceback" not in err


def test_the_readmes_mount_file_loads_on_the_builtin_vehicle(tmp_path: Path) -> None:
    """The mount.parm docs/vehicles.md gives ArduCopter (and the no-gimbal error names): the same
    file on our vehicle, SERVOn_FUNCTION included."""
    parm = tmp_path / "mount.parm"
    parm.write_text(
        "MNT1_TYPE 1\nMNT1_PITCH_MIN -90\nMNT1_PITCH_MAX 0\nSERVO9_FUNCTION 7\nSERVO10_FUNCTION 6\n"
    )
    result = CliRunner().invoke(cli, ["sitl", "--params", str(parm), "--duration", "0.5"])
    assert result.exit_code == 0, result.output
    assert "stopped at sim time" in result.output


def test_a_fleet_answers_on_each_vehicles_port_with_its_own_sysid() -> None:
    """``--vehicles 2``: vehicle 2 on the first endpoint's port + 10 as sysid 2 (ArduPilot's
    ``-I1``), flown by one client while vehicle 1 stays on the ground; the summary on exit
    gives the closest approach."""
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "uavtool", "sitl", "--vehicles", "2", "--speedup", "5",
         "--endpoint", f"tcpin:127.0.0.1:{port}"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        banner = "".join(proc.stdout.readline() for _ in range(4))
        assert "2 vehicles on offset line 90,10" in banner
        assert "vehicle sysid 2 at" in banner and f"tcpin:127.0.0.1:{port + 10}" in banner
        script = f"""
import os
os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil
one = mavutil.mavlink_connection("tcp:127.0.0.1:{port}", source_system=255)
two = mavutil.mavlink_connection("tcp:127.0.0.1:{port + 10}", source_system=255)
print("sysids", one.wait_heartbeat(timeout=10).get_srcSystem(),
      two.wait_heartbeat(timeout=10).get_srcSystem())
two.target_system = 2
two.set_mode("GUIDED")
while not two.motors_armed():
    two.arducopter_arm()
    two.recv_match(type="HEARTBEAT", blocking=True, timeout=1)
two.mav.command_long_send(2, 1, mavutil.mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 0, 5)
while two.recv_match(type="GLOBAL_POSITION_INT", blocking=True, timeout=10).relative_alt < 4800:
    pass
print("one at", one.recv_match(type="GLOBAL_POSITION_INT", blocking=True).relative_alt)
"""
        out = subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False
        )
        assert out.returncode == 0, out.stderr
        lines = out.stdout.splitlines()
        assert lines[0] == "sysids 1 2"
        assert abs(int(lines[1].split()[2])) < 100  # vehicle 1 never left the ground
    finally:
        proc.send_signal(signal.SIGINT)
        rest, _ = proc.communicate(timeout=10)
    assert "closest approach: vehicles 1 and 2, bodies" in rest
    assert "crashed" not in rest
