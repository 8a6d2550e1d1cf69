"""`uavtool view REC --save out.rrd`: the file, read back with Rerun's own reader, holds
what the recording holds, on the recording's timelines, with the default blueprint."""

from __future__ import annotations

import itertools
from pathlib import Path

from tests.view.conftest import Facts, Saved
from tests.view.rrd import read_rrd, views
from uavtool.view import view

TELEMETRY = (
    "altitude_m",
    "speed_m_s",
    "climb_m_s",
    "heading_deg",
    "gimbal_pitch_deg",
    "battery_pct",
)


def test_reports_what_it_wrote(saved: Saved, facts: Facts) -> None:
    assert saved.stdout.startswith(f"wrote {saved.path}: {facts.frames} frames, ")
    assert f"{facts.telemetry} telemetry samples" in saved.stdout
    assert saved.data.application_id == "uavtool"


def test_entity_paths(saved: Saved) -> None:
    expected = {
        "world",
        "world/scene/ground",
        "world/vehicle",
        "world/vehicle/body",
        "world/camera",
        "world/camera/image",
        "world/camera/image/overlay",
        "world/camera/image/overlay/shapes",
        "world/camera/image/overlay/pois",
        "world/camera/image/overlay/match",
        "world/photos",
        "world/pois",
        "world/viewpoints",
        "world/viewpoints/footprint",
        "world/model",
        "world/model/mesh",
        "target",
        "target/shapes",
        "map/vehicle",
        "log/mission",
        "log/vehicle",
        "log/commands",
        "plots/recognition/threshold",
        *(f"plots/telemetry/{name}" for name in TELEMETRY),
        *(f"world/scene/buildings/{name}" for name in ("yellow", "purple", "blue", "red")),
    }
    assert expected <= saved.data.entities()
    assert "world/route/0000" in saved.data.entities()


def test_timelines_are_the_recordings(saved: Saved) -> None:
    data = saved.data
    for entity in (
        "world/vehicle",
        "world/camera/image",
        "plots/telemetry/altitude_m",
        "log/mission",
    ):
        assert data.timelines[entity] == {"vehicle_time", "log_time"}, entity
    # vehicle time is the vehicle's boot time: the frames are seconds into the flight
    frame_times = [
        r["vehicle_time"] for r in data.rows["world/camera/image"] if "EncodedImage:blob" in r
    ]
    assert frame_times == sorted(frame_times)
    assert 1e9 < frame_times[0] < frame_times[-1] < 3600e9
    # ground truth and the target picture do not depend on time
    assert {"world", "world/scene/buildings/red", "target", "target/shapes"} <= data.static


def test_one_frame_per_camera_image(saved: Saved, facts: Facts) -> None:
    data = saved.data
    assert len(data.column("world/camera/image", "EncodedImage:blob")) == facts.frames
    assert len(data.column("world/camera/image", "Pinhole:image_from_camera")) == facts.frames
    assert len(data.column("world/camera", "Transform3D:translation")) == facts.frames
    # each new frame clears the previous frame's overlay
    assert len(data.column("world/camera/image/overlay", "Clear:is_recursive")) == facts.frames
    photos = data.last("world/photos")
    assert len(photos["Points3D:positions"]) == facts.frames
    assert photos["Points3D:labels"][0] == "overview"
    assert photos["Points3D:labels"][-4:] == ["top", "front", "right", "diagonal"]


def test_telemetry_in_bulk_and_the_route_complete(saved: Saved, facts: Facts) -> None:
    data = saved.data
    for name in TELEMETRY:
        assert len(data.rows[f"plots/telemetry/{name}"]) == facts.telemetry + 1, name  # + style
    assert len(data.column("world/vehicle", "Transform3D:translation")) == facts.telemetry
    assert len(data.column("map/vehicle", "GeoPoints:positions")) == facts.telemetry
    chunks = sorted(data.entities("world/route/"))
    strips = [data.last(c)["LineStrips3D:strips"][0] for c in chunks]
    # every chunk starts where the previous one ended; together they hold every sample once
    for before, after in itertools.pairwise(strips):
        assert after[0] == before[-1]
    assert sum(len(s) for s in strips) - (len(strips) - 1) == facts.telemetry
    altitudes = data.column("plots/telemetry/altitude_m", "Scalars:scalars")
    assert max(v[0] for v in altitudes) > 40.0  # the overview climb


def test_every_shape_is_drawn(saved: Saved, facts: Facts) -> None:
    data = saved.data
    drawn = sum(
        len(r) for r in data.column("world/camera/image/overlay/shapes", "LineStrips2D:strips")
    )
    drawn += sum(len(r) for r in data.column("target/shapes", "LineStrips2D:strips"))
    assert drawn == facts.strips


def test_points_of_interest_and_the_match(saved: Saved, facts: Facts) -> None:
    data = saved.data
    pois = data.last("world/pois")
    assert len(pois["Points3D:positions"]) == facts.pois
    assert facts.matched_poi is not None
    label = pois["Points3D:labels"][facts.matched_poi]
    assert "MATCH" in label
    assert all(" m)" in text and "(roof " in text for text in pois["Points3D:labels"])
    assert pois["Points3D:radii"][facts.matched_poi] == max(pois["Points3D:radii"])
    scores = sum(len(data.rows[e]) for e in data.entities("plots/recognition/poi_"))
    assert scores == facts.recognitions
    assert (
        len(data.column("world/camera/image/overlay/match", "LineStrips2D:strips"))
        == facts.recognitions
    )
    overview_marks = data.column("world/camera/image/overlay/pois", "Points2D:positions")
    assert [len(m) for m in overview_marks] == [facts.pois]


def test_model_beside_the_true_building(saved: Saved, facts: Facts) -> None:
    data = saved.data
    meshes = data.column("world/model/mesh", "Mesh3D:vertex_positions")
    assert [len(m) for m in meshes] == [facts.model_vertices]
    ((offset,),) = data.column("world/model", "Transform3D:translation")
    xs = [v[0] for v in meshes[0]]
    assert offset[0] > max(xs) - min(xs)  # moved clear of the building it models
    assert offset[1:] == [0.0, 0.0]


def test_text_log_has_vehicle_and_mission_lines(saved: Saved, facts: Facts) -> None:
    data = saved.data
    vehicle = [t[0] for t in data.column("log/vehicle", "TextLog:text")]
    statustexts = [t for t in vehicle if not t.startswith("mode ")]
    assert len(statustexts) == facts.statustexts
    assert any(t.startswith("mode GUIDED") for t in vehicle)
    mission = [t[0] for t in data.column("log/mission", "TextLog:text")]
    assert any("MATCH" in t for t in mission)
    assert mission[-1].startswith("outcome: completed")


def test_default_blueprint(saved: Saved) -> None:
    found = views(saved.blueprint)
    assert ("3D", "3D", "world") in found
    assert ("2D", "camera", "world/camera/image") in found
    assert ("2D", "target", "target") in found
    assert ("TextLog", "log", "log") in found
    assert {name for kind, name, _ in found if kind == "TimeSeries"} == {
        "altitude & speed",
        "recognition scores",
        "heading & gimbal",
        "battery",
    }
    panel = saved.blueprint.last("time_panel")
    assert panel["TimePanelBlueprint:timeline"] == ["vehicle_time"]


def test_compare_shows_a_second_recording_beside(
    recording: Path, tmp_path: Path, facts: Facts
) -> None:
    out = tmp_path / "both.rrd"
    result = view(recording, save=out, compare=recording)
    assert result.compare_counts == result.counts
    data, blueprint = read_rrd(out)
    assert len(data.column("compare/world/camera/image", "EncodedImage:blob")) == facts.frames
    assert len(data.column("world/camera/image", "EncodedImage:blob")) == facts.frames
    spatial = {(kind, origin) for kind, _, origin in views(blueprint) if kind in ("2D", "3D")}
    assert {("3D", "world"), ("3D", "compare/world")} <= spatial
    assert {("2D", "world/camera/image"), ("2D", "compare/world/camera/image")} <= spatial
    # both missions' telemetry on the same axes, told apart in the legend
    (legend,) = data.column("compare/plots/telemetry/altitude_m", "SeriesLines:names")
    assert legend == ["altitude above home (m) [compare]"]
