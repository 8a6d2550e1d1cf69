"""Topic names of a mission recording (README, "Recording format"): shared by the runner that
writes them and by replay and the viewer that read them."""

from __future__ import annotations

OBSERVATIONS = "/mission/observations"
"""Every observation, in the order the mission consumed it (JSON, numbered by ``step``)."""
OUTPUTS = "/mission/outputs"
"""Every output, in order (JSON, numbered by ``n``, with the ``step`` that produced it)."""
TARGET = "/mission/target"
EVENTS = "/mission/events"
MODEL = "/mission/model"
IMAGE = "/camera/image"
CALIBRATION = "/camera/calibration"
CAMERA_POSE = "/camera/pose"
FIX = "/vehicle/fix"
POSE = "/vehicle/pose"
