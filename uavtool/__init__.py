"""uavtool: fly, record, replay and view vision missions for MAVLink drones."""

__version__ = "0.1.0"
"""This package's version: ``pyproject.toml`` reads it from here. A literal, not
``importlib.metadata.version``: importing that costs every process ~25 ms (the recording's
writer process too)."""

__all__ = ["__version__"]
