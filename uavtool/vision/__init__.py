"""Vision (paper section III): vectorize frames, recognize shapes, build 3D models.

Every stage is a pure function of its inputs and one typed parameter structure: no I/O, no
clock, no global state, so replay reproduces it bit for bit. OpenCV runs single-threaded
inside each stage (``cv2.setNumThreads(1)`` at the entry points).
"""

from __future__ import annotations

from uavtool.vision.params import ModelParams, RecognizeParams, VectorizeParams
from uavtool.vision.recognize import Match, best_match, match, match_shapes, mirror_score
from uavtool.vision.shapes import Shape
from uavtool.vision.vectorize import vectorize

__all__ = [
    "Match",
    "ModelParams",
    "RecognizeParams",
    "Shape",
    "VectorizeParams",
    "best_match",
    "match",
    "match_shapes",
    "mirror_score",
    "vectorize",
]
