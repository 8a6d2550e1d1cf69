"""`uavtool view FLEET --save out.rrd`: a fleet's recording (``fly --vehicles 2``), read back
with Rerun's own reader, shows every vehicle under its own entities, each in its own frame
placed at its home, so the routes stand where they were flown; the target, the scene and
the fleet's outcome once, for all."""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner

from tests.view.rrd import Store, read_rrd, views
from uavtool.cli import cli
from uavtool.geo import GeoPoint, enu_from_geo
from uavtool.recording import RecordingReader
from uavtool.runner.fleet import fly_fleet
from uavtool.runner.fly import FlyConfig
from uavtool.view import FleetVehicle, MissionLogger, ViewError, log_recording, view
from uavtool.view.session import open_viewer

VEHICLES = (1, 2)
# South-east, 12 m apart: vehicle 2's home is off both axes, so a lost east or north shows.
OFFSET_LINE = (120.0, 12.0)


@dataclass(frozen=True)
class Vehicle:
    """What the recording holds of one vehicle, read from the MCAP itself."""

    home_en_m: tuple[float, float]
    frames: int
    telemetry: list[list[float]]  # own frame, one per sample with a vehicle time
    fixes: list[GeoPoint]  # one per telemetry sample, on the map
    photos: list[list[float]]  # each photo's camera position, own frame
    outputs: dict[str, dict[str, Any]]  # the last output of each type
    statustexts: int


@dataclass(frozen=True)
class Fleet:
    path: Path
    stdout: str
    data: Store
    blueprint: Store
    vehicles: dict[int, Vehicle]
    outcome: dict[str, str]


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Fleet:
    folder = tmp_path_factory.mktemp("fleet-view")
    rec = folder / "fleet.mcap"
    config = FlyConfig(
        mission="fleet-search", vehicles=len(VEHICLES), offset_line=OFFSET_LINE, record=rec
    )
    fly_fleet(config)  # ~2 s: the leader surveys, vehicle 2 looks and builds the model
    out = folder / "fleet.rrd"
    result = CliRunner().invoke(cli, ["view", str(rec), "--save", str(out)])
    assert result.exit_code == 0, result.output
    data, blueprint = read_rrd(out)
    vehicles, outcome = _facts(rec)
    return Fleet(out, result.stdout, data, blueprint, vehicles, outcome)


def _facts(rec: Path) -> tuple[dict[int, Vehicle], dict[str, str]]:
    with RecordingReader(rec) as reader:
        meta = dict(reader.metadata)
        homes = [(float(e), float(n)) for e, n in json.loads(meta["crew"]["homes_en_m"])]
        counts = {reader.channels[i].topic: n for i, n in reader.message_counts.items()}
        senders = Counter(
            e.value.payload["header"]["sysid"] for e in reader.entries(["/mavlink/in/STATUSTEXT"])
        )
        vehicles = {}
        for k in VEHICLES:
            telemetry, photos, outputs = [], [], {}
            for e in reader.entries([f"/uav{k}/mission/observations", f"/uav{k}/mission/outputs"]):
                d = e.value.payload
                if d["type"] == "Telemetry" and d["time_boot_ms"] > 0:
                    telemetry.append(d["pos_enu_m"])
                elif d["type"] == "Photo":
                    photos.append(d["pose"]["pos_enu_m"])
                elif e.topic.endswith("/outputs"):
                    outputs[d["type"]] = d
            fixes = [
                GeoPoint(f.value.latitude_deg, f.value.longitude_deg, f.value.altitude_m)
                for f in reader.entries([f"/uav{k}/vehicle/fix"])
            ]
            vehicles[k] = Vehicle(
                homes[k - 1],
                counts[f"/uav{k}/camera/image"],
                telemetry,
                fixes,
                photos,
                outputs,
                senders[k],
            )
    return vehicles, meta["outcome"]


def _route(data: Store, k: int) -> list[list[float]]:
    """Vehicle ``k``'s route as drawn: its chunks joined (each starts where the last ended)."""
    points: list[list[float]] = []
    for chunk in sorted(data.entities(f"world/uav{k}/route/")):
        strip = data.last(chunk)["LineStrips3D:strips"][0]
        points += strip[1:] if points else strip
    return points


def _close(got: Any, expected: Any, atol: float) -> None:
    np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=0.0, atol=atol)


def _placed(data: Store, k: int) -> list[float]:
    """Where vehicle ``k``'s frame stands in the fleet's world (its static transform)."""
    assert f"world/uav{k}" in data.static
    ((translation,),) = data.column(f"world/uav{k}", "Transform3D:translation")
    return [float(c) for c in translation]


def test_reports_every_vehicle(fleet: Fleet) -> None:
    frames = sum(v.frames for v in fleet.vehicles.values())
    assert fleet.stdout.startswith(f"wrote {fleet.path}: 2 vehicles, {frames} frames, ")
    telemetry = sum(len(v.telemetry) for v in fleet.vehicles.values())
    assert f"{telemetry} telemetry samples" in fleet.stdout
    assert ", 1 model" in fleet.stdout


def test_each_vehicle_under_its_own_entities(fleet: Fleet) -> None:
    entities = fleet.data.entities()
    for k in VEHICLES:
        assert {
            f"world/uav{k}",
            f"world/uav{k}/route/0000",
            f"world/uav{k}/vehicle",
            f"world/uav{k}/vehicle/body",
            f"world/uav{k}/camera",
            f"world/uav{k}/camera/image",
            f"world/uav{k}/camera/image/overlay/shapes",
            f"world/uav{k}/photos",
            f"plots/uav{k}/telemetry/altitude_m",
            f"log/uav{k}/mission",
            f"log/uav{k}/vehicle",
            f"map/uav{k}/vehicle",
        } <= entities, k
    # the fleet's own, once: the scene, the target, its outcome
    assert {"world", "world/scene/buildings/red", "target", "target/shapes", "log/fleet"} <= (
        entities
    )
    assert {"world", "world/scene/ground", "target"} <= fleet.data.static
    # no vehicle's entity where one vehicle's view puts its own
    assert not entities & {"world/vehicle", "world/camera", "world/photos", "map/vehicle"}
    assert not fleet.data.entities("world/route/") and not fleet.data.entities("log/mission")


def test_each_route_is_its_telemetry_placed_at_its_home(fleet: Fleet) -> None:
    for k, v in fleet.vehicles.items():
        assert _placed(fleet.data, k) == pytest.approx([*v.home_en_m, 0.0], abs=1e-4)
        route = _route(fleet.data, k)
        _close(route, v.telemetry, 1e-4)  # in its own frame
        poses = fleet.data.column(f"world/uav{k}/vehicle", "Transform3D:translation")
        _close([p[0] for p in poses], v.telemetry, 1e-4)
    home2 = fleet.vehicles[2].home_en_m
    assert home2[0] > 5.0 and home2[1] < -3.0  # south-east of vehicle 1's
    # Vehicle 2 takes off from its own home: the first point of its route, in the world,
    # is its home, not vehicle 1's.
    first = [a + b for a, b in zip(_route(fleet.data, 2)[0], _placed(fleet.data, 2), strict=True)]
    assert first == pytest.approx([*home2, 0.0], abs=0.05)


def test_where_the_3d_view_draws_each_vehicle_is_where_it_flew(fleet: Fleet) -> None:
    """Every route point, moved into the fleet's world, is the vehicle's recorded position on
    the map (its /uavK/vehicle/fix), seen from vehicle 1's home: the fleet's frame."""
    origin = fleet.vehicles[1].fixes[0]  # vehicle 1 at its home, before take-off
    for k, v in fleet.vehicles.items():
        placed = _placed(fleet.data, k)
        route = _route(fleet.data, k)
        assert len(route) == len(v.fixes)
        for point, fix in list(zip(route, v.fixes, strict=True))[::50]:
            world = [a + b for a, b in zip(point, placed, strict=True)]
            assert world == pytest.approx(list(enu_from_geo(origin, fix)), abs=0.05), k
        # and the map shows it there too, from the vehicle's own home
        (last,) = fleet.data.last(f"map/uav{k}/vehicle")["GeoPoints:positions"]
        assert last == pytest.approx([v.fixes[-1].lat_deg, v.fixes[-1].lon_deg], abs=1e-6)


def test_each_vehicle_shows_its_camera_frames(fleet: Fleet) -> None:
    data = fleet.data
    for k, v in fleet.vehicles.items():
        assert v.frames > 0
        image = f"world/uav{k}/camera/image"
        assert len(data.column(image, "EncodedImage:blob")) == v.frames
        assert len(data.column(image, "Pinhole:image_from_camera")) == v.frames
        cameras = data.column(f"world/uav{k}/camera", "Transform3D:translation")
        _close([c[0] for c in cameras], v.photos, 1e-4)
        assert len(data.last(f"world/uav{k}/photos")["Points3D:positions"]) == v.frames


def test_findings_in_the_fleet_frame_stand_where_the_mission_put_them(fleet: Fleet) -> None:
    """A member's positions are in the fleet's frame, its entities in its own: the view moves
    them by its home, so in the world they are where the mission said."""
    data = fleet.data
    builder = fleet.vehicles[2]  # the helper at the target built the model
    placed = _placed(data, 2)
    model = builder.outputs["ModelBuilt"]
    (mesh,) = data.column("world/uav2/model/mesh", "Mesh3D:vertex_positions")
    _close(mesh, model["vertices_m"], 1e-4)
    ((offset,),) = data.column("world/uav2/model", "Transform3D:translation")
    xs = [v[0] for v in model["vertices_m"]]
    beside = [max(xs) - min(xs) + 4.0, 0.0, 0.0]  # as one vehicle's: clear of the building
    assert [a + b for a, b in zip(offset, placed, strict=True)] == pytest.approx(beside, abs=1e-3)
    top = builder.outputs["Viewpoints"]["top"]["pos_enu_m"]
    drawn = data.last("world/uav2/viewpoints")["Points3D:positions"][0]
    assert [a + b for a, b in zip(drawn, placed, strict=True)] == pytest.approx(top, abs=1e-3)
    # the leader's points of interest (its home is the fleet frame's origin)
    pois = fleet.vehicles[1].outputs["Plan"]["pois"]
    drawn_pois = data.last("world/uav1/pois")["Points3D:positions"]
    _close([p[:2] for p in drawn_pois], [p["pos_en_m"] for p in pois], 1e-4)
    assert data.entities("plots/uav2/recognition/poi_")


def test_shared_channels_go_to_the_vehicle_that_sent_them(fleet: Fleet) -> None:
    data = fleet.data
    for k, v in fleet.vehicles.items():
        said = [t[0] for t in data.column(f"log/uav{k}/vehicle", "TextLog:text")]
        assert len([t for t in said if not t.startswith("mode ")]) == v.statustexts > 0
        mission = [t[0] for t in data.column(f"log/uav{k}/mission", "TextLog:text")]
        assert mission[-1].startswith("outcome: completed")
    (line,) = data.column("log/fleet", "TextLog:text")
    assert line == [f"fleet outcome: completed: {fleet.outcome['reason']}; closest approach "
                    f"{fleet.outcome['closest_approach_m']} m (kept: 5 m)"]  # fmt: skip
    (legend,) = data.column("plots/uav2/telemetry/altitude_m", "SeriesLines:names")
    assert legend == ["altitude above home (m) [uav2]"]


def test_the_layout_shows_every_vehicle(fleet: Fleet) -> None:
    found = views(fleet.blueprint)
    assert ("3D", "3D", "world") in found  # the one world holds them all
    cameras = {(name, origin) for kind, name, origin in found if kind == "2D"}
    assert cameras == {
        ("camera: uav1", "world/uav1/camera/image"),
        ("camera: uav2", "world/uav2/camera/image"),
        ("target", "target"),
    }
    assert ("TextLog", "log", "log") in found and ("Map", "map", "map") in found
    queries = [
        q
        for e in fleet.blueprint.entities("view/")
        for q in fleet.blueprint.column(e, "ViewContents:query")
    ]
    altitude = next(q for q in queries if "+ /plots/uav1/telemetry/altitude_m" in q)
    assert "+ /plots/uav2/telemetry/altitude_m" in altitude


def test_compare_with_a_fleet_is_refused(fleet: Fleet, tmp_path: Path) -> None:
    rec = fleet.path.with_suffix(".mcap")
    with pytest.raises(ViewError, match="--compare with a fleet's recording"):
        view(rec, save=tmp_path / "both.rrd", compare=rec)
    assert not list(tmp_path.iterdir())


def test_one_vehicles_logger_refuses_a_fleet(fleet: Fleet, tmp_path: Path) -> None:
    viewer = open_viewer(save=tmp_path / "one.rrd")
    try:
        assert isinstance(viewer.logger, MissionLogger)
        with pytest.raises(ViewError, match="log_fleet_recording shows every vehicle"):
            log_recording(fleet.path.with_suffix(".mcap"), viewer.logger)
    finally:
        viewer.close()


def test_a_large_fleets_cameras_stand_in_a_grid(tmp_path: Path) -> None:
    fleet = [FleetVehicle(k, (10.0 * (k - 1), 0.0)) for k in range(1, 7)]
    viewer = open_viewer(save=tmp_path / "six.rrd", fleet=fleet)
    assert viewer.fleet is not None and sorted(viewer.fleet.vehicles) == [1, 2, 3, 4, 5, 6]
    viewer.close()
    data, blueprint = read_rrd(tmp_path / "six.rrd")
    cameras = sorted(origin for kind, _, origin in views(blueprint) if kind == "2D")
    assert cameras == sorted([*(f"world/uav{k}/camera/image" for k in range(1, 7)), "target"])
    grids = [
        row["ContainerBlueprint:grid_columns"]
        for e in blueprint.entities("container/")
        for row in blueprint.rows[e]
        if row.get("ContainerBlueprint:grid_columns")
    ]
    assert grids == [[4]]
    # each vehicle's frame placed at its home before anything is flown
    assert _placed(data, 6) == pytest.approx([50.0, 0.0, 0.0])
    assert "world/uav6/vehicle/body" in data.static
