"""``uavtool fly --rerun``: the flight streamed to Rerun while it happens, through the same
logger ``uavtool view`` uses for recordings (so live and replayed views are the same)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uavtool.geo import GeoPoint
from uavtool.images import png_encode
from uavtool.mission import Observation, Output, Photo
from uavtool.mission.codec import encode_observation, encode_output
from uavtool.runner.record import ClockNs
from uavtool.world import Scene


class LiveView:
    """Sends each observation and output to a Rerun viewer (``rerun`` = ``"spawn"``,
    ``"web"`` — on ``web_port``, reading from ``grpc_port`` — or a ``.rrd`` path), stamped by
    the recording's clock ``clock_ns``."""

    def __init__(
        self,
        target: str,
        *,
        web_port: int | None = None,
        grpc_port: int | None = None,
        scene: Scene | None,
        params: dict[str, Any],
        target_png: bytes | None,
        clock_ns: ClockNs,
    ) -> None:
        from uavtool.view import open_viewer  # noqa: PLC0415 - rerun is heavy; only with --rerun

        if target == "web":
            self.viewer = open_viewer(web=True, web_port=web_port, grpc_port=grpc_port)
        elif target == "spawn":
            self.viewer = open_viewer()
        else:
            self.viewer = open_viewer(save=Path(target))
        self.url = self.viewer.url
        self.logger = self.viewer.logger
        if scene is not None:
            self.logger.scene(scene)
        self.logger.params(params)
        if target_png is not None:
            self.logger.target(target_png)
        self._n = 0
        self.clock_ns = clock_ns

    def home(self, home: GeoPoint) -> None:
        self.logger.home(home)

    def observation(self, step: int, obs: Observation, png: bytes | None = None) -> None:
        """Show one observation; a photo's frame as ``png`` if the caller encoded it."""
        if png is None and isinstance(obs, Photo):
            png = png_encode(obs.image_rgb)
        self.logger.observation(step, encode_observation(obs), png, log_time_ns=self.clock_ns())

    def outputs(self, step: int, outputs: list[Output]) -> None:
        t = self.clock_ns()
        for out in outputs:
            self._n += 1
            self.logger.output(
                self._n, {"n": self._n, "step": step, **encode_output(out)}, log_time_ns=t
            )

    def close(self) -> None:
        self.viewer.flush()
        self.viewer.close()
