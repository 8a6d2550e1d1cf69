"""Navigation (paper section IV): pixels to ground offsets, viewpoints, visiting order.

Pure functions in plain float and ``math`` scalars, so the mission's decisions replay bit
for bit. Frames: local ENU metres around home; headings in degrees clockwise from north.
"""

from __future__ import annotations

from uavtool.nav.errors import NavError, NavParamError
from uavtool.nav.projection import (
    frame_corners_px,
    frame_on_plane,
    ground_point,
    ground_polygon,
    poi_offset,
)
from uavtool.nav.rect import Rect, min_area_rect
from uavtool.nav.route import route_length_m, visit_order
from uavtool.nav.viewpoints import (
    Viewpoint,
    ViewpointFailure,
    ViewpointParams,
    plan_diagonal,
    plan_towards,
    plan_viewpoints,
    top_viewpoint,
)

__all__ = [
    "NavError",
    "NavParamError",
    "Rect",
    "Viewpoint",
    "ViewpointFailure",
    "ViewpointParams",
    "frame_corners_px",
    "frame_on_plane",
    "ground_point",
    "ground_polygon",
    "min_area_rect",
    "plan_diagonal",
    "plan_towards",
    "plan_viewpoints",
    "poi_offset",
    "route_length_m",
    "top_viewpoint",
    "visit_order",
]
