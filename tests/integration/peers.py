"""The real autopilots the integration tests fly against, found through environment variables
(``.ci/run`` sets them when ``../shared/peers`` is there; without them the tests skip and say
why), run faster than real time (``SPEEDUP``): the mission is timed by the vehicle's clock, so
the same flight works at any speed-up.

- ``UAVTOOL_ARDUCOPTER``: a built ``arducopter`` binary (``./waf copter``), ArduPilot's
  ``copter.parm`` beside it or in the source tree it was built in.
- ``UAVTOOL_PX4``: PX4's SITL build, a ``px4_sitl_default`` folder (``bin/px4``, ``etc``) or
  its ``.tar.gz``; flown with SIH, PX4's built-in simulator.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tarfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from uavtool.camera import CameraPose
from uavtool.geo import GeoPoint
from uavtool.mission import Photo
from uavtool.replay import load_flight
from uavtool.world import load_scene, render

ARDUCOPTER = os.environ.get("UAVTOOL_ARDUCOPTER", "")
PX4 = os.environ.get("UAVTOOL_PX4", "")
SPEEDUP = float(os.environ.get("UAVTOOL_PEER_SPEEDUP", "5"))
"""How much faster than real time the autopilots run (both take a speed factor)."""
PX4_GIMBAL = {
    "MNT_MODE_IN": "4",  # MAVLink gimbal protocol v2
    "MNT_MODE_OUT": "0",  # AUX outputs: the simulated mount
    "MNT_MIN_PITCH": "-90",
    "MNT_MAX_PITCH": "0",
}
PX4_API_PORT = 14540
"""PX4 SITL's onboard/API link sends here (MAVSDK's default); its GCS link sends to 14550."""


def uavtool(*args: str) -> list[str]:
    """The command line that runs ``uavtool ARGS`` at a lower CPU priority than the autopilot.

    The autopilots run SPEEDUP times faster than real time, on the wall clock. On a two-core
    machine, PX4 starved for a moment by uavtool's processes misses its own simulated sensors'
    deadlines ("BARO #0 failed: TIMEOUT!", seen once in CI) and fails over to land: a test of
    the machine, not of uavtool. On a drone the autopilot has a processor of its own; here the
    scheduler gives it first claim. uavtool keeps time by the vehicle's clock, so being
    scheduled later changes nothing it decides."""
    return ["nice", "-n", "10", sys.executable, "-m", "uavtool", *args]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _copter_defaults() -> Path:
    """ArduPilot's copter.parm: beside the binary (a prebuilt SITL, as ../shared/peers lays
    it out), else in the source tree the binary was built in (build/sitl/bin/arducopter)."""
    binary = Path(ARDUCOPTER).resolve()
    beside = binary.parent / "copter.parm"
    if beside.is_file():
        return beside
    return binary.parents[3] / "Tools" / "autotest" / "default_params" / "copter.parm"


@contextmanager
def arducopter(tmp_path: Path, *, params: str = "", home: str, instance: int = 0) -> Iterator[int]:
    """ArduCopter SITL with ``params`` (a .parm file's text) over its defaults, as instance
    ``instance`` (``-I``: its simulator's own ports apart from the others'); yields the TCP
    port its MAVLink listens on."""
    defaults = [str(_copter_defaults())]
    if params:
        parm = tmp_path / "extra.parm"
        parm.write_text(params)
        defaults.append(str(parm))
    port = free_port()
    cmd = [
        ARDUCOPTER, "--model", "+", "--home", home, "--defaults", ",".join(defaults),
        "--serial0", f"tcp:{port}", "--wipe", f"-I{instance}", "--speedup", f"{SPEEDUP:g}",
    ]  # fmt: skip
    proc = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    try:
        time.sleep(2.0)
        yield port
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def _px4_build(tmp_path: Path) -> Path:
    """The px4_sitl_default folder: UAVTOOL_PX4 itself, or its tarball unpacked once."""
    given = Path(PX4)
    if given.is_dir():
        return given
    cache = Path(os.environ.get("UAVTOOL_PX4_UNPACKED", tmp_path.parent / "px4-unpacked"))
    build = cache / "px4_sitl_default"
    if not (build / "bin" / "px4").is_file():
        cache.mkdir(parents=True, exist_ok=True)
        with tarfile.open(given) as tar:
            tar.extractall(cache, filter="tar" if sys.version_info >= (3, 12) else None)
    return build


@contextmanager
def px4(
    tmp_path: Path,
    *,
    params: dict[str, str] | None = None,
    instance: int = 0,
    home: GeoPoint | None = None,
) -> Iterator[int]:
    """PX4 SITL with SIH (quadrotor X) and ``params`` set at boot, in a fresh rootfs, as
    instance ``instance`` (``px4 -i N``: MAV_SYS_ID N + 1, its API link on 14540 + N), at
    ``home`` (else PX4's own); yields the UDP port its API link sends to, once it says it is
    ready for take-off."""
    build = _px4_build(tmp_path)
    rootfs = tmp_path / "rootfs"
    rootfs.mkdir()
    at = {}
    if home is not None:
        at = {
            "PX4_HOME_LAT": f"{home.lat_deg:.7f}",
            "PX4_HOME_LON": f"{home.lon_deg:.7f}",
            "PX4_HOME_ALT": f"{home.alt_amsl_m:.2f}",
        }
    env = {
        **os.environ,
        "PX4_SYS_AUTOSTART": "10040",
        "PX4_SIM_MODEL": "sihsim_quadx",
        "PX4_SIMULATOR": "sihsim",
        "PX4_SIM_SPEED_FACTOR": f"{SPEEDUP:g}",
        **at,
        **{f"PX4_PARAM_{k}": v for k, v in (params or {}).items()},
    }
    log = tmp_path / "px4.log"
    with log.open("wb") as out:
        proc = subprocess.Popen(
            [str(build / "bin" / "px4"), "-i", str(instance), "-d", str(build / "etc")],
            cwd=rootfs, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
    try:
        deadline = time.monotonic() + 60.0
        while b"Ready for takeoff" not in log.read_bytes():
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"PX4 did not become ready:\n{log.read_text()[-2000:]}")
            time.sleep(0.2)
        yield PX4_API_PORT + instance
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def fly(connect: str, tmp_path: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        uavtool("fly", "--connect", connect, "--timeout", "120",
                "--output", str(tmp_path / "f.mcap"), *extra),
        capture_output=True, text=True, timeout=1800, check=False,
    )  # fmt: skip


def check_photo_poses(recording: Path, *, at_least: int) -> None:
    """Each photo's pose, as the autopilot reported it: nadir photos point straight down,
    side photos level, headings in [0, 360), and the scene rendered again at the pose recorded
    is the photo recorded, closer than turned by 180°. A heading off by 180° gives another
    picture where the view is not alike both ways round: most nadir photos must show it
    clearly (a photo over a building alone in plain ground may look alike turned; where an
    autopilot on the wall clock takes it varies from run to run)."""
    flight = load_flight(recording)
    scene = load_scene("paper")  # placed at the vehicle's home: its own frame
    photos = [o for o in flight.observations if isinstance(o, Photo)]
    assert len(photos) >= at_least
    nadir = telling = 0
    for photo in photos:
        pose = photo.pose
        side = photo.tag.split("-")[0] in ("front", "right", "diagonal")
        assert abs(pose.pitch_deg - (0.0 if side else -90.0)) < 1.0, (photo.tag, pose)
        assert 0.0 <= pose.heading_deg < 360.0, (photo.tag, pose)
        again = render(scene, pose, photo.intrinsics).astype(np.int16)
        turned = CameraPose(pose.pos_enu_m, (pose.heading_deg + 180.0) % 360.0, pose.pitch_deg)
        other = render(scene, turned, photo.intrinsics).astype(np.int16)
        shot = photo.image_rgb.astype(np.int16)
        same, flipped = np.abs(shot - again).mean(), np.abs(shot - other).mean()
        assert same < 1.0 and (side or flipped > same), (photo.tag, same, flipped)
        if not side:
            nadir += 1
            telling += flipped > 5.0 * max(same, 0.2)
    assert telling * 2 >= nadir > 0, (telling, nadir)


def fly_fleet_search(connects: list[str], tmp_path: Path) -> None:
    """``uavtool fly --mission fleet-search`` on one ``--connect`` each: it completes with the
    right building's model, the separation kept, and its recording replays identically."""
    args = [a for url in connects for a in ("--connect", url)]
    result = subprocess.run(
        uavtool("fly", "--mission", "fleet-search", *args, "--timeout", "120",
                "--output", str(tmp_path / "f.mcap")),
        capture_output=True, text=True, timeout=2400, check=False,
    )  # fmt: skip
    out = result.stdout + result.stderr
    assert result.returncode == 0, out
    assert "outcome        completed" in result.stdout, out
    assert "match          building 'red' (right" in result.stdout, out
    assert "(kept: 5 m)" in result.stdout, out
    check = subprocess.run(
        uavtool("replay", "--check", str(tmp_path / "f.mcap")),
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
