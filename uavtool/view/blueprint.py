"""The default layout: what a person sees on first opening a mission in Rerun.

Left, the 3D world (buildings, route, photo positions, points of interest, viewpoints,
model) above the camera (latest frame with its vectors); right, the plots, the target and
the text log. With a second recording, its 3D view and camera stand beside the first and
its plots are drawn on the same axes.
"""

from __future__ import annotations

import rerun.blueprint as rrb

from uavtool.view.paths import COMPARE_PREFIX, VEHICLE_TIME, Paths

_ALL = rrb.TimeRangeBoundary.infinite()


def default_blueprint(*, compare: bool = False) -> rrb.Blueprint:
    """The layout for one mission, or for one beside a second (under ``compare/``)."""
    main = Paths()
    other = Paths(COMPARE_PREFIX)
    if compare:
        spatial: rrb.Container = rrb.Vertical(
            rrb.Horizontal(_world(main, "3D: recording"), _world(other, "3D: compared")),
            rrb.Horizontal(_camera(main, "camera: recording"), _camera(other, "camera: compared")),
            row_shares=[3, 2],
        )
    else:
        spatial = rrb.Vertical(_world(main, "3D"), _camera(main, "camera"), row_shares=[3, 2])
    side = rrb.Vertical(
        _plots(main, other if compare else None),
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


def _plots(main: Paths, other: Paths | None) -> rrb.Tabs:
    roots = [main] if other is None else [main, other]

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
