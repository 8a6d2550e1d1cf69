"""The default layout: what a person sees on first opening a mission in Rerun.

Left, the 3D world (buildings, route, photo positions, points of interest, viewpoints,
model) above the camera (latest frame with its vectors); right, the plots, the target and
the text log. With a second recording, its 3D view and camera stand beside the first and
its plots are drawn on the same axes. A fleet's 3D view holds every vehicle, with a camera
view per vehicle below it; every vehicle's plots are drawn on the same axes.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb

from uavtool.view.paths import COMPARE_PREFIX, VEHICLE_TIME, Paths

_ALL = rrb.TimeRangeBoundary.infinite()
_CAMERAS_IN_A_ROW = 4


def default_blueprint(*, compare: bool = False, fleet: Sequence[str] = ()) -> rrb.Blueprint:
    """The layout for one mission, for one beside a second (under ``compare/``), or for a
    fleet's (``fleet``: its vehicles' names, ``uav1`` …)."""
    main = Paths()
    other = Paths(COMPARE_PREFIX)
    plotted = [main, other] if compare else [main]
    if fleet:
        vehicles = [Paths(uav=name) for name in fleet]
        spatial: rrb.Container = rrb.Vertical(
            _world(main, "3D"), _cameras(vehicles), row_shares=[3, 2]
        )
        plotted = vehicles
    elif compare:
        spatial = rrb.Vertical(
            rrb.Horizontal(_world(main, "3D: recording"), _world(other, "3D: compared")),
            rrb.Horizontal(_camera(main, "camera: recording"), _camera(other, "camera: compared")),
            row_shares=[3, 2],
        )
    else:
        spatial = rrb.Vertical(_world(main, "3D"), _camera(main, "camera"), row_shares=[3, 2])
    side = rrb.Vertical(
        _plots(plotted, main),
        rrb.Horizontal(
            rrb.Spatial2DView(origin=main.target, name="target"),
            _logs(main, other if compare else None),
            column_shares=[1, 2],
        ),
        row_shares=[3, 2],
    )
    return rrb.Blueprint(
        rrb.Horizontal(spatial, side, column_shares=[3, 2]),
        rrb.TimePanel(timeline=VEHICLE_TIME, state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )


def _world(paths: Paths, name: str) -> rrb.Spatial3DView:
    return rrb.Spatial3DView(
        origin=paths.world,
        name=name,
        background=(24, 26, 32),
        # A bird's-eye view from south-west of home, like the paper's route figures.
        eye_controls=rrb.EyeControls3D(
            kind=rrb.Eye3DKind.Orbital,
            position=(-22.0, -48.0, 38.0),
            look_target=(2.0, -2.0, 8.0),
            eye_up=(0.0, 0.0, 1.0),
        ),
    )


def _camera(paths: Paths, name: str) -> rrb.Spatial2DView:
    return rrb.Spatial2DView(origin=paths.image, name=name)


def _cameras(vehicles: Sequence[Paths]) -> rrb.Container:
    """A fleet's cameras, one view per vehicle: in a row, or a grid when they are many."""
    views = [_camera(p, f"camera: {p.uav}") for p in vehicles]
    if len(views) <= _CAMERAS_IN_A_ROW:
        return rrb.Horizontal(*views)
    return rrb.Grid(*views, grid_columns=_CAMERAS_IN_A_ROW)


def _plots(roots: Sequence[Paths], main: Paths) -> rrb.Tabs:
    """Each series of every root (mission, compared mission, vehicle) on the same axes; the
    map of ``main`` (all that is under it)."""

    def series(name: str, *subs: str) -> rrb.TimeSeriesView:
        contents = [f"+ /{p.plots}/{sub}" for sub in subs for p in roots]
        # The whole flight on the x axis, not the window around the time cursor.
        axis = rrb.TimeAxis(view_range=rrb.TimeRange(start=_ALL, end=_ALL))
        return rrb.TimeSeriesView(origin="/", contents=contents, name=name, axis_x=axis)

    return rrb.Tabs(
        series(
            "altitude & speed", "telemetry/altitude_m", "telemetry/speed_m_s", "telemetry/climb_m_s"
        ),
        series("recognition scores", "recognition/**"),
        series("heading & gimbal", "telemetry/heading_deg", "telemetry/gimbal_pitch_deg"),
        series("battery", "telemetry/battery_pct"),
        rrb.MapView(origin=main.map, name="map"),
        name="plots",
    )


def _logs(main: Paths, other: Paths | None) -> rrb.TextLogView:
    if other is None:
        return rrb.TextLogView(origin=main.log, name="log")
    return rrb.TextLogView(
        origin="/", contents=[f"+ /{main.log}/**", f"+ /{other.log}/**"], name="log"
    )
