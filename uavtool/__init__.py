"""uavtool: fly, record, replay and view vision missions for MAVLink drones."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("uavtool")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.0.0"

__all__ = ["__version__"]
