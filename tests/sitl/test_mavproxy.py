"""MAVProxy, run headless as a user would, sees a healthy ArduCopter in ``uavtool sitl``.

What counts as a warning line
-----------------------------
Headless (no console or map module; commands typed on stdin) MAVProxy prints its own
status lines and the vehicle's STATUSTEXTs, prefixed ``AP:``, with no colour to tell an
error from a note. So the test checks every line against the lines MAVProxy prints for a
healthy ArduCopter flying exactly this session (``_EXPECTED``: connect, heartbeat, mode
changes, "fence present", GPS lock, parameters received and saved, ACCEPTED command
acknowledgements, "Arming motors", ARMED/DISARMED, "Taking off", height read-outs, "Land
complete: disarming", the output of the commands we type, and the modules unloaded on
exit). **Any other line is a
warning**: "fence breach", "Unknown command"/"unknown mode", a COMMAND_ACK that is not
ACCEPTED, "PreArm: …", "Auto disarm: landed", "link 1 down"/"no link", a traceback, or
anything new.

One exception, because ArduCopter does the same: for a few seconds of sim time after boot
the vehicle refuses to arm (``uavtool.sitl.prearm``). We retry ``arm throttle`` as a user
would, and before the first ARMED each refusal may print ``AP: Arm: Gyros inconsistent`` or
``AP: Arm: Need Position Estimate`` (those two reasons only) and ``Got COMMAND_ACK:
COMPONENT_ARM_DISARM: FAILED``, at most once per ``arm throttle`` we sent. After ARMED the
same lines are warnings.

The console would colour STATUSTEXTs by severity; MAVProxy's telemetry log keeps it, so the
test also reads that log: no STATUSTEXT at MAV_SEVERITY_WARNING or worse but those boot
refusals.
"""

from __future__ import annotations

import os
import queue
import re
import socket
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.link.sitl_process import sitl_process
from tests.sitl.mavproxy_env import mavproxy_command
from uavtool.mavlink import FrameParser
from uavtool.mavlink import mavlink as M
from uavtool.sitl.params import PARAM_SPECS

SPEEDUP = 5
BOOT_REFUSALS = ("Gyros inconsistent", "Need Position Estimate")

_PROMPT = re.compile(r"[A-Z][A-Z0-9_]*> ?")
"""MAVProxy's prompt ("MAV> ", "GUIDED> "): with stdin a pipe it lands mid-line."""

_EXPECTED = [
    re.compile(p)
    for p in (
        r"Connect tcp:127\.0\.0\.1:\d+ source_system=255",
        r"Log Directory: .*",
        r"Telemetry log: .*mav\.tlog",
        r"Waiting for heartbeat from tcp:127\.0\.0\.1:\d+",
        r"Detected vehicle 1:1 on link 0",
        r"online system 1",
        r"Mode (STABILIZE|GUIDED|LAND)",
        r"fence present",  # GEOFENCE "present" bit, as ArduCopter's FENCE_TYPE sets it
        r"GPS lock at \d+ meters",
        r"Received \d+ parameters",
        r"Saved \d+ parameters to .*mav\.parm",
        r"Got COMMAND_ACK: (DO_SET_MODE|COMPONENT_ARM_DISARM|NAV_TAKEOFF): ACCEPTED",
        r"AP: Arming motors",
        r"ARMED",
        r"Taking off to 10\.0 meters",
        r"height \d+",  # MAVProxy's altitude read-out every 10 m
        r"AP: Land complete: disarming",
        r"DISARMED",
        r"\d+: GLOBAL_POSITION_INT \{.*\}",  # our `status GLOBAL_POSITION_INT`
        r"Unloading module \w+",  # on exit
    )
]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class MavProxy:
    """A headless ``mavproxy.py`` whose stdin we type into and whose lines we read."""

    def __init__(self, command: list[str], port: int, home: Path) -> None:
        env = {**os.environ, "PYTHONUNBUFFERED": "1", "HOME": str(home)}  # no ~/.mavinit.scr
        env.pop("DISPLAY", None)
        self.proc = subprocess.Popen(
            [
                *command,
                f"--master=tcp:127.0.0.1:{port}",
                f"--state-basedir={home}",
            ],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            bufsize=1,
            cwd=home,
            env=env,
        )
        self.lines: list[str] = []  # every line, prompts removed, in order
        self._queue: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for raw in self.proc.stdout:
            self._queue.put(_PROMPT.sub("", raw).strip())
        self._queue.put(None)

    def type(self, command: str) -> None:
        assert self.proc.stdin is not None
        self.lines.append(f">>> {command}")
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()

    def expect(self, *patterns: str, timeout: float = 10.0) -> re.Match[str]:
        """The first new line matching any of ``patterns`` (the others are kept)."""
        compiled = [re.compile(p) for p in patterns]
        end = time.monotonic() + timeout
        while (left := end - time.monotonic()) > 0:
            try:
                line = self._queue.get(timeout=left)
            except queue.Empty:
                break
            if line is None:
                break
            if line:
                self.lines.append(line)
            for c in compiled:
                if m := c.fullmatch(line):
                    return m
        transcript = "\n".join(self.lines)
        raise AssertionError(f"MAVProxy never printed {patterns}:\n{transcript}")

    def close(self) -> None:
        """Quit (EOF on stdin) and collect the rest of the output; idempotent."""
        if self.proc.stdin is None or self.proc.stdin.closed:
            return
        self.proc.stdin.close()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self._reader.join(timeout=5)
        assert self.proc.stdout is not None
        self.proc.stdout.close()
        while not self._queue.empty():
            if line := self._queue.get():
                self.lines.append(line)


@pytest.fixture
def session(tmp_path: Path) -> Iterator[MavProxy]:
    """``uavtool sitl --speedup 5`` and MAVProxy connected to it, as docs/sitl.md shows."""
    command = mavproxy_command()  # MAVProxy's own environment (see mavproxy_env)
    port = _free_port()
    with sitl_process(f"tcpin:127.0.0.1:{port}", "--speedup", str(SPEEDUP)):
        mavproxy = MavProxy(command, port, tmp_path)
        try:
            yield mavproxy
        finally:
            mavproxy.close()


_EXIT_RACE = re.compile(r"AttributeError: 'NoneType' object has no attribute '\w+'")
_EXCEPTION = re.compile(r"[\w.]+(Error|Exception|Exit|Interrupt)\b")
"""The last line of a whole traceback: the exception's type."""


def _without_exit_race(lines: list[str]) -> list[str]:
    """``lines`` less MAVProxy's own race at exit, seen on a loaded machine: once it unloads
    its modules on EOF, its main loop thread may still run and find the global state already
    gone (``Exception in thread main_loop:`` … ``AttributeError: 'NoneType' object has no
    attribute 'input_queue'``, every frame in MAVProxy or threading). The interpreter may
    end while that daemon thread prints, cutting the traceback short, down to its first
    line alone: a cut traceback at the very end of the output counts too when the frames it
    shows are MAVProxy's or threading's. Any other traceback, or this one before exit,
    stays a warning."""
    try:
        exiting = next(i for i, line in enumerate(lines) if line.startswith("Unloading module"))
    except StopIteration:
        return lines
    start = next(
        (i for i in range(exiting, len(lines)) if lines[i] == "Exception in thread main_loop:"),
        None,
    )
    if start is None:
        return lines
    end = next((i for i in range(start, len(lines)) if _EXIT_RACE.fullmatch(lines[i])), None)
    if end is None:  # cut short, if the process ended while the thread printed
        if any(_EXCEPTION.match(line) for line in lines[start + 1 :]):
            return lines  # a whole traceback, of another exception
        end = len(lines) - 1
    frames = [line for line in lines[start : end + 1] if line.startswith("File ")]
    if not all("/MAVProxy/" in f or "/threading.py" in f for f in frames):
        return lines
    return lines[:start] + lines[end + 1 :]


def _altitude_m(mavproxy: MavProxy) -> float:
    mavproxy.type("status GLOBAL_POSITION_INT")
    m = mavproxy.expect(r"\d+: GLOBAL_POSITION_INT \{.*relative_alt : (-?\d+),.*\}", timeout=5)
    return int(m.group(1)) / 1000


def _statustexts(tlog: Path) -> list[tuple[int, str]]:
    """(severity, text) of every STATUSTEXT in a MAVProxy telemetry log (frames after 8-byte
    timestamps; the parser resynchronises past the timestamps)."""
    return [
        (f.msg.severity, f.msg.text)
        for f in FrameParser().feed(tlog.read_bytes())
        if f.msg.get_type() == "STATUSTEXT"
    ]


@pytest.mark.slow
def test_connect_params_guided_arm_takeoff_land_without_warnings(
    session: MavProxy, tmp_path: Path
) -> None:
    mp = session
    received = mp.expect(r"Received (\d+) parameters", timeout=20)
    assert int(received.group(1)) == len(PARAM_SPECS)

    mp.type("mode guided")
    mp.expect(r"Mode GUIDED")

    arm_commands = 0
    deadline = time.monotonic() + 20
    while True:  # refused while the vehicle boots, like ArduCopter: retry as a user would
        mp.type("arm throttle")
        arm_commands += 1
        if mp.expect(r"ARMED", r".*COMPONENT_ARM_DISARM: FAILED").group(0) == "ARMED":
            break
        assert time.monotonic() < deadline, "the vehicle never armed"
        time.sleep(0.5)

    mp.type("takeoff 10")  # at once: DISARM_DELAY is 10 s of sim time, 2 s at 5x
    mp.expect(r"Taking off to 10\.0 meters")
    deadline = time.monotonic() + 20
    while _altitude_m(mp) < 9.5:
        assert time.monotonic() < deadline, "never reached 10 m"
        time.sleep(0.3)

    mp.type("mode land")
    mp.expect(r"Mode LAND")
    mp.expect(r"DISARMED", timeout=30)
    assert abs(_altitude_m(mp)) < 0.3
    mp.close()

    armed_at = mp.lines.index("ARMED")
    refusals = 0
    warnings = []
    lines = _without_exit_race(mp.lines)
    for i, line in enumerate(lines):
        if line.startswith(">>> ") or any(p.fullmatch(line) for p in _EXPECTED):
            continue
        booting = i < armed_at
        if booting and line in {f"AP: Arm: {why}" for why in BOOT_REFUSALS}:
            refusals += 1
            continue
        if booting and line == "Got COMMAND_ACK: COMPONENT_ARM_DISARM: FAILED":
            continue
        warnings.append(line)
    transcript = "\n".join(mp.lines)
    assert not warnings, f"MAVProxy warned: {warnings}\n--- transcript:\n{transcript}"
    assert refusals <= arm_commands - 1, transcript

    texts = _statustexts(tmp_path / "mav.tlog")
    assert (M.MAV_SEVERITY_INFO, "Arming motors") in texts
    severe = [
        (severity, text)
        for severity, text in texts
        if severity <= M.MAV_SEVERITY_WARNING
        and text not in {f"Arm: {why}" for why in BOOT_REFUSALS}
    ]
    assert not severe, severe
    assert (tmp_path / "mav.parm").read_text().count("\n") >= len(PARAM_SPECS)


_EXITING = ["DISARMED", "Unloading module link"]
_HEADER = ["Exception in thread main_loop:", "Traceback (most recent call last):"]


@pytest.mark.parametrize(
    ("tail", "forgiven"),
    [
        (_HEADER[:1], True),  # the interpreter ended right after the thread's first line
        ([*_HEADER, 'File "/v/MAVProxy/mavproxy.py", line 9, in main_loop'], True),
        (
            [
                *_HEADER,
                'File "/v/MAVProxy/mavproxy.py", line 9',
                "x",
                "AttributeError: 'NoneType' object has no attribute 'input_queue'",
            ],
            True,
        ),
        ([*_HEADER, 'File "/v/uavtool/x.py", line 9'], False),  # cut, but not MAVProxy's
        ([*_HEADER, 'File "/v/MAVProxy/mavproxy.py", line 9', "x", "KeyError: 3"], False),
    ],
)
def test_only_mavproxys_own_exit_race_is_forgiven(tail: list[str], forgiven: bool) -> None:
    kept = _without_exit_race([*_EXITING, *tail])
    assert kept == (_EXITING if forgiven else [*_EXITING, *tail])
