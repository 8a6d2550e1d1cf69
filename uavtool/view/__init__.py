"""Missions in Rerun: ``uavtool view`` (a recording) and ``uavtool fly --rerun`` (live).

>>> from uavtool.view import view
>>> result = view("recordings/golden/paper.mcap", save="paper.rrd")  # doctest: +SKIP
>>> result.counts.frames  # doctest: +SKIP
8

Live, the runner logs each observation and output through the same `MissionLogger`::

    viewer = open_viewer(web=True)          # or save=..., or neither: native viewer
    viewer.logger.scene(scene); viewer.logger.home(home); viewer.logger.target(png)
    viewer.logger.observation(step, obs_dict, image_png, log_time_ns=t)
    viewer.logger.output(n, out_dict, log_time_ns=t)
    viewer.close()

A fleet's recording (``uavtool fly --vehicles N``) goes through a `FleetLogger`: one
`MissionLogger` per vehicle, its entities under ``world/uavK/…`` placed at its home.
"""

from uavtool.view.blueprint import default_blueprint
from uavtool.view.errors import ViewError
from uavtool.view.fleet import FleetLogger
from uavtool.view.fleet_source import fleet_of, log_fleet_recording
from uavtool.view.logger import LogCounts, MissionLogger, statustext_level
from uavtool.view.paths import COMPARE_PREFIX, LOG_TIME, VEHICLE_TIME, FleetVehicle, Paths
from uavtool.view.session import APPLICATION_ID, Viewer, ViewResult, open_viewer, view
from uavtool.view.source import log_recording

__all__ = [
    "APPLICATION_ID",
    "COMPARE_PREFIX",
    "LOG_TIME",
    "VEHICLE_TIME",
    "FleetLogger",
    "FleetVehicle",
    "LogCounts",
    "MissionLogger",
    "Paths",
    "ViewError",
    "ViewResult",
    "Viewer",
    "default_blueprint",
    "fleet_of",
    "log_fleet_recording",
    "log_recording",
    "open_viewer",
    "statustext_level",
    "view",
]
