"""Where the entities go: a ``.rrd`` file, the native viewer, or the web viewer.

`open_viewer` makes one Rerun recording stream with its sink and the default blueprint,
and a `MissionLogger` on it; `view` feeds it a recording (and a second one to compare).
`uavtool fly --rerun` uses `open_viewer` and calls the logger as the mission runs.
"""

from __future__ import annotations

import uuid
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

import rerun as rr

from uavtool.recording.files import atomic_output
from uavtool.view.blueprint import default_blueprint
from uavtool.view.errors import ViewError
from uavtool.view.logger import LogCounts, MissionLogger
from uavtool.view.paths import COMPARE_PREFIX
from uavtool.view.source import log_recording

APPLICATION_ID = "uavtool"


class Viewer:
    """An open Rerun stream: ``logger`` logs into it; ``url`` is the web viewer's address
    when serving one. ``close`` flushes and finishes the file or stops the servers."""

    def __init__(self, rec: rr.RecordingStream, *, batch: int, url: str | None) -> None:
        self.rec = rec
        self.url = url
        self.logger = MissionLogger(rec, batch=batch)

    def compare_logger(self) -> MissionLogger:
        """A logger for a second mission shown beside the first (entities under ``compare/``)."""
        return MissionLogger(self.rec, prefix=COMPARE_PREFIX, batch=self.logger.batch)

    def flush(self) -> None:
        self.logger.flush()
        self.rec.flush()

    def close(self) -> None:
        self.flush()
        self.rec.disconnect()


def open_viewer(
    *,
    save: str | Path | None = None,
    web: bool = False,
    web_port: int | None = None,
    grpc_port: int | None = None,
    compare: bool = False,
    batch: int = 10,
) -> Viewer:
    """A stream to ``save`` (a ``.rrd`` file), to a web viewer on ``web_port`` (``web``), or
    to a newly spawned native viewer (neither). ``batch``: telemetry samples per send.
    Raises `ViewError` if the file cannot be written or the servers cannot start."""
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    # Our log_time is the recording's receive time, not the time of this conversion.
    rec.set_log_time_enabled(False)
    blueprint = default_blueprint(compare=compare)
    url = None
    try:
        if save is not None:
            Path(save).parent.mkdir(parents=True, exist_ok=True)
            rec.save(save, default_blueprint=blueprint)
        elif web:
            grpc_url = rec.serve_grpc(grpc_port=grpc_port, default_blueprint=blueprint)
            port = 9090 if web_port is None else web_port
            rr.serve_web_viewer(web_port=port, open_browser=False, connect_to=grpc_url)
            url = f"http://localhost:{port}/?url={quote(grpc_url, safe='')}"
        else:
            rec.spawn(default_blueprint=blueprint)
    except (OSError, RuntimeError, ValueError) as exc:
        where = save if save is not None else ("the web viewer" if web else "the native viewer")
        raise ViewError(f"{where}: cannot open: {exc}") from None
    return Viewer(rec, batch=batch, url=url)


@dataclass(frozen=True, slots=True)
class ViewResult:
    """The viewer (still serving with ``web``) and what was logged for the recording and
    the compared one."""

    viewer: Viewer
    counts: LogCounts
    compare_counts: LogCounts | None

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
    return _view(path, save=None, web=web, compare=compare, web_port=web_port, grpc_port=grpc_port)


def _view(
    path: str | Path,
    *,
    save: Path | None,
    web: bool,
    compare: str | Path | None,
    web_port: int | None = None,
    grpc_port: int | None = None,
) -> ViewResult:
    viewer = open_viewer(
        save=save,
        web=web,
        web_port=web_port,
        grpc_port=grpc_port,
        compare=compare is not None,
        batch=1 << 30,
    )
    try:
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
    return ViewResult(viewer, viewer.logger.counts, other)
