"""Topic names of a recording: shared by the runner and the recorder that write them and by
replay and the viewer that read them. docs/recording-format.md lists every topic, with its
encoding and schema; tests/test_docs.py checks that table against this module."""

from __future__ import annotations

OBSERVATIONS = "/mission/observations"
"""Every observation, in the order the mission consumed it (JSON, numbered by ``step``)."""
OUTPUTS = "/mission/outputs"
"""Every output, in order (JSON, numbered by ``n``, with the ``step`` that produced it)."""
TARGET = "/mission/target"
EVENTS = "/mission/events"
MODEL = "/mission/model"
PICTURES = "/mission/pictures"
"""Images a mission made (``Picture`` outputs: a mosaic, a map), PNG, ``frame_id`` = tag."""
SCENE = "/mission/scene"
"""The route flown, photo poses, points of interest and viewpoints (`foxglove.SceneUpdate`)."""
IMAGE = "/camera/image"
CALIBRATION = "/camera/calibration"
CAMERA_POSE = "/camera/pose"
FIX = "/vehicle/fix"
POSE = "/vehicle/pose"

# A flight recorded by `uavtool record` (no mission): the vehicle's state and the camera's
# frames with their poses, instead of the mission's observations.
TELEMETRY = "/vehicle/telemetry"
"""Every telemetry sample (JSON, as a ``Telemetry`` observation)."""
FRAMES = "/camera/frames"
"""One per ``/camera/image`` frame, in the same order (JSON: a ``Photo`` observation plus
``photo``, ``trigger``, ``pose_time_boot_ms``, ``pose_dt_ms``)."""
VEHICLE_EVENTS = "/vehicle/events"
"""Mode changes, arming, STATUSTEXT, mission progress, photos (``foxglove.Log``)."""
VISION = "/vision/results"
"""``replay --vision-only`` of such a recording: per photo, its ``Shapes`` and
``Recognition`` against the target (JSON, as the mission's outputs)."""
