"""Monte Carlo sweeps of simulated flights on Dask (``uavtool sweep``) and batch replay of
many recordings (``uavtool replay DIR``).

A spec (:mod:`~uavtool.sweep.spec`) expands into flights (:mod:`~uavtool.sweep.plan`); each
flies in lockstep as a Dask task (:mod:`~uavtool.sweep.task`) into the sweep's folder
(:mod:`~uavtool.sweep.layout`); the driver (:mod:`~uavtool.sweep.run`) submits them through a
bounded window (:mod:`~uavtool.sweep.dispatch`) and gathers the rows into a table
(:mod:`~uavtool.sweep.table`), a summary and plots.
"""

from uavtool.sweep.errors import FlightTimeoutError, OutputExistsError, SpecError
from uavtool.sweep.plan import FlightSpec, plan_flights
from uavtool.sweep.progress import Progress, format_progress
from uavtool.sweep.run import SweepResult, run_sweep
from uavtool.sweep.spec import SweepSpec, load_spec

__all__ = [
    "FlightSpec",
    "FlightTimeoutError",
    "OutputExistsError",
    "Progress",
    "SpecError",
    "SweepResult",
    "SweepSpec",
    "format_progress",
    "load_spec",
    "plan_flights",
    "run_sweep",
]
