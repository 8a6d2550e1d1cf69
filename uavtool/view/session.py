"""Where the entities go: a ``.rrd`` file, the native viewer, or the web viewer.

`open_viewer` makes one Rerun recording stream with its sink and the default blueprint,
and a `MissionLogger` on it (with a fleet, a `FleetLogger` too); `view` feeds it a recording
(and a second one to compare). `uavtool fly --rerun` uses `open_viewer` and calls the logger
as the mission runs.
"""

from __future__ import annotations

import contextlib
import errno
import importlib.util
import os
import shutil
import socket
import subprocess
import sys
import time
import uuid
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

import rerun as rr

from uavtool.recording.files import atomic_output
from uavtool.view.blueprint import default_blueprint
from uavtool.view.errors import PortInUseError, ViewError
from uavtool.view.fleet import FleetLogger
from uavtool.view.fleet_source import fleet_of, log_fleet_recording
from uavtool.view.logger import LogCounts, MissionLogger
from uavtool.view.paths import COMPARE_PREFIX, FleetVehicle
from uavtool.view.source import log_recording

APPLICATION_ID = "uavtool"


LOCALHOST = "127.0.0.1"
"""Where the web viewer's servers listen unless the user asks for another address."""

WEB_PORT = 9090
"""The web viewer's port unless the user asks for another (Rerun's own default)."""

GRPC_PORT = 9876
"""The port of the server the web viewer reads from (Rerun's own default)."""


class Viewer:
    """An open Rerun stream: ``logger`` logs into it; ``url`` is the web viewer's address
    when serving one. ``close`` flushes and finishes the file or stops the servers.

    For a fleet (``fleet``: its vehicles), ``fleet`` is the `FleetLogger` that logs every
    vehicle, and ``logger`` is its first vehicle's."""

    def __init__(
        self,
        rec: rr.RecordingStream,
        *,
        batch: int,
        url: str | None,
        server: subprocess.Popen[bytes] | None = None,
        fleet: Sequence[FleetVehicle] = (),
    ) -> None:
        self.rec = rec
        self.url = url
        self.fleet = FleetLogger(rec, fleet, batch=batch) if fleet else None
        if self.fleet is None:
            self.logger = MissionLogger(rec, batch=batch)
        else:
            self.logger = self.fleet.vehicles[fleet[0].sysid]
        self._server = server

    def compare_logger(self) -> MissionLogger:
        """A logger for a second mission shown beside the first (entities under ``compare/``)."""
        return MissionLogger(self.rec, prefix=COMPARE_PREFIX, batch=self.logger.batch)

    def flush(self) -> None:
        if self.fleet is not None:
            self.fleet.flush()
        self.logger.flush()
        self.rec.flush()

    def close(self) -> None:
        self.flush()
        self.rec.disconnect()
        if self._server is not None:  # the web viewer's servers go with us
            self._server.terminate()
            try:
                self._server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._server.kill()
                self._server.wait()


def open_viewer(
    *,
    save: str | Path | None = None,
    web: bool = False,
    web_port: int | None = None,
    grpc_port: int | None = None,
    bind: str = LOCALHOST,
    compare: bool = False,
    batch: int = 10,
    fleet: Sequence[FleetVehicle] = (),
) -> Viewer:
    """A stream to ``save`` (a ``.rrd`` file), to a web viewer on ``web_port`` reading from
    ``grpc_port`` (``web``; None: `WEB_PORT`, `GRPC_PORT`), or to a newly spawned native
    viewer (neither). ``batch``: telemetry samples per send; ``fleet``: the vehicles of a
    fleet to show (its layout, and `Viewer.fleet`). Raises `ViewError` if the file cannot be
    written or the servers cannot start (`PortInUseError`: a port is taken)."""
    if web and save is None:
        port, grpc = _web_ports(bind, web_port, grpc_port)
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    # Our log_time is the recording's receive time, not the time of this conversion.
    rec.set_log_time_enabled(False)
    blueprint = default_blueprint(compare=compare, fleet=[v.name for v in fleet])
    url = None
    server = None
    try:
        if save is not None:
            Path(save).parent.mkdir(parents=True, exist_ok=True)
            rec.save(save, default_blueprint=blueprint)
        elif web:
            server = _serve_web(bind, grpc, port)
            grpc_url = f"rerun+http://{_host(bind)}:{grpc}/proxy"
            rec.connect_grpc(grpc_url, default_blueprint=blueprint)
            url = f"http://{_host(bind)}:{port}/?url={quote(grpc_url, safe='')}"
        else:
            rec.spawn(default_blueprint=blueprint)
    except (OSError, RuntimeError, ValueError) as exc:
        if server is not None:
            server.kill()
        where = save if save is not None else ("the web viewer" if web else "the native viewer")
        raise ViewError(f"{where}: cannot open: {exc}") from None
    return Viewer(rec, batch=batch, url=url, server=server, fleet=fleet)


def _serve_web(bind: str, grpc_port: int, web_port: int) -> subprocess.Popen[bytes]:
    """Rerun's own server, as a child process: its gRPC proxy and web viewer bound to
    ``bind`` (the SDK's in-process servers listen on every interface and take no address)."""
    cmd = [*_die_with_us(), _rerun_binary(), "--serve-web", "--bind", bind]
    cmd += ["--port", str(grpc_port), "--web-viewer-port", str(web_port)]
    env = dict(os.environ, RERUN_ANALYTICS="0")
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=env,
        start_new_session=True,  # Ctrl-C is ours to handle: we stop it, whole
    )
    deadline = time.monotonic() + _SERVER_START_S
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            why = (proc.stderr.read() if proc.stderr else b"").decode(errors="replace").strip()
            last = why.splitlines()[-1] if why else f"exit {proc.returncode}"
            raise OSError(f"Rerun's server stopped: {last[-200:]}")
        with contextlib.suppress(OSError), socket.create_connection((_host(bind), grpc_port), 0.2):
            return proc
        time.sleep(0.1)
    proc.kill()
    raise OSError(f"Rerun's server did not listen on port {grpc_port} in {_SERVER_START_S:g} s")


_SERVER_START_S = 30.0


def _rerun_binary() -> str:
    """The rerun-sdk's own ``rerun`` executable (``python -m rerun`` would run it as a second
    process, which stopping the first would leave behind)."""
    spec = importlib.util.find_spec("rerun_cli")  # installed with rerun-sdk
    if spec is None or spec.origin is None:
        raise OSError("rerun-sdk's rerun_cli is not installed")
    folder = Path(spec.origin).parent
    found = next((p for p in (folder / "rerun", folder / "rerun.exe") if p.is_file()), None)
    if found is None:
        raise OSError(f"rerun-sdk's rerun executable is not in {folder}")
    return str(found)


def _die_with_us() -> list[str]:
    """A prefix that stops the server when uavtool stops, however it stops (a kill must not
    leave a server listening): util-linux's ``setpriv --pdeathsig`` where there is one."""
    setpriv = shutil.which("setpriv") if sys.platform.startswith("linux") else None
    return [setpriv, "--pdeathsig", "TERM"] if setpriv else []


def _host(bind: str) -> str:
    """The address to reach a server bound to ``bind`` at (every interface: this machine)."""
    return LOCALHOST if bind in ("0.0.0.0", "::", "") else bind


def _web_ports(bind: str, web_port: int | None, grpc_port: int | None) -> tuple[int, int]:
    """The web viewer's port and its data server's (None: the defaults), both free."""
    port = WEB_PORT if web_port is None else web_port
    grpc = GRPC_PORT if grpc_port is None else grpc_port
    if port == grpc:
        raise ViewError(
            f"--web-port and --grpc-port are both {port}: the web viewer and its data server "
            "need a port each"
        )
    _check_free(bind, port, "--web-port")
    _check_free(bind, grpc, "--grpc-port")
    return port, grpc


def _check_free(bind: str, port: int, option: str) -> None:
    """`PortInUseError` when something already listens on ``port`` at ``bind``. Bound as
    Rerun's server binds (SO_REUSEADDR), so a port left in TIME_WAIT counts as free."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(
            bind or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
        )[0]
    except (OSError, UnicodeError) as exc:
        raise ViewError(f"--bind {bind}: not an address to listen on: {exc}") from None
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            if exc.errno != errno.EADDRINUSE:
                raise ViewError(f"--bind {bind}: cannot listen there: {exc.strerror}") from None
            raise PortInUseError(
                f"{option} {port}: already in use on {bind} (another viewer?); choose another "
                "port, or stop what holds it"
            ) from None


@dataclass(frozen=True, slots=True)
class ViewResult:
    """The viewer (still serving with ``web``) and what was logged for the recording and
    the compared one; for a fleet's recording, ``counts`` adds up its vehicles' and
    ``vehicle_counts`` gives each one's, by system id."""

    viewer: Viewer
    counts: LogCounts
    compare_counts: LogCounts | None
    vehicle_counts: Mapping[int, LogCounts] = field(default_factory=dict)

    @property
    def url(self) -> str | None:
        return self.viewer.url


def view(
    path: str | Path,
    *,
    save: str | Path | None = None,
    web: bool = False,
    compare: str | Path | None = None,
    web_port: int | None = None,
    grpc_port: int | None = None,
    bind: str = LOCALHOST,
) -> ViewResult:
    """Show the recording at ``path`` (and ``compare`` beside it) in Rerun; see
    `open_viewer` for the sinks. With ``save`` the file is complete on return; with ``web``
    the caller keeps the process alive while the returned `Viewer` serves, then closes it.
    Raises `NotMcapError` / `ViewError` for a file that is not a mission recording, and
    `SameFileError` if ``save`` is one of the recordings. ``save`` appears only once it is
    complete: nothing is left behind when the view fails."""
    if save is not None:
        with atomic_output(save, inputs=[path, compare]) as tmp:
            return _view(path, save=tmp, web=False, compare=compare)
    return _view(
        path,
        save=None,
        web=web,
        compare=compare,
        web_port=web_port,
        grpc_port=grpc_port,
        bind=bind,
    )


def _view(
    path: str | Path,
    *,
    save: Path | None,
    web: bool,
    compare: str | Path | None,
    web_port: int | None = None,
    grpc_port: int | None = None,
    bind: str = LOCALHOST,
) -> ViewResult:
    fleet = fleet_of(path)
    if compare is not None and (fleet or fleet_of(compare)):
        raise ViewError(
            f"--compare with a fleet's recording ({compare if not fleet else path}): not yet; "
            "view each on its own"
        )
    viewer = open_viewer(
        save=save,
        web=web,
        web_port=web_port,
        grpc_port=grpc_port,
        bind=bind,
        compare=compare is not None,
        batch=1 << 30,
        fleet=fleet,
    )
    try:
        if viewer.fleet is not None:
            log_fleet_recording(path, viewer.fleet)
        else:
            log_recording(path, viewer.logger)
        other = None
        if compare is not None:
            compare_logger = viewer.compare_logger()
            log_recording(compare, compare_logger)
            other = compare_logger.counts
        viewer.flush()
    except BaseException:
        viewer.rec.disconnect()  # no flush: the data may be what failed
        raise
    if save is not None:
        viewer.close()
    if viewer.fleet is not None:
        return ViewResult(viewer, viewer.fleet.counts, other, viewer.fleet.vehicle_counts)
    return ViewResult(viewer, viewer.logger.counts, other)
