"""Entity paths and timeline names: the layout of a mission in Rerun.

Everything one recording shows lives under one prefix ("" for the recording being viewed,
``compare`` for a second one shown beside it), so two missions never share an entity. A
fleet's vehicle puts its entities one level down, under its name (``uav2``): ``world/uav2/…``,
``plots/uav2/…``, ``log/uav2/…`` beside the other vehicles', around the fleet's shared world
(the scene) and target.
"""

from __future__ import annotations

from dataclasses import dataclass

VEHICLE_TIME = "vehicle_time"
"""Duration timeline: the vehicle's time since boot (MAVLink ``time_boot_ms``)."""
LOG_TIME = "log_time"
"""Timestamp timeline: when the ground station received the message (the MCAP log time)."""

COMPARE_PREFIX = "compare"


@dataclass(frozen=True, slots=True)
class Paths:
    """Entity paths of one mission under ``prefix`` (no leading or trailing slash); of one
    vehicle of a fleet with ``uav`` (its name, ``uav2``)."""

    prefix: str = ""
    uav: str = ""

    def _at(self, path: str) -> str:
        if self.uav:  # world/route → world/uav2/route
            head, _, tail = path.partition("/")
            path = f"{head}/{self.uav}/{tail}" if tail else f"{head}/{self.uav}"
        return self._shared(path)

    def _shared(self, path: str) -> str:
        """A path of the whole recording, a fleet's vehicle or not (the target)."""
        return f"{self.prefix}/{path}" if self.prefix else path

    @property
    def world(self) -> str:
        return self._at("world")

    @property
    def buildings(self) -> str:
        return self._at("world/scene/buildings")

    def building(self, name: str) -> str:
        return f"{self.buildings}/{_safe(name)}"

    @property
    def ground(self) -> str:
        return self._at("world/scene/ground")

    @property
    def route(self) -> str:
        return self._at("world/route")

    def route_chunk(self, index: int) -> str:
        return f"{self.route}/{index:04d}"

    @property
    def vehicle(self) -> str:
        return self._at("world/vehicle")

    @property
    def vehicle_body(self) -> str:
        return self._at("world/vehicle/body")

    @property
    def camera(self) -> str:
        """Transform of the camera when it took the latest photo."""
        return self._at("world/camera")

    @property
    def image(self) -> str:
        """Pinhole and the latest frame (camera optical frame: x right, y down, z forward)."""
        return self._at("world/camera/image")

    @property
    def overlay(self) -> str:
        """What the vision found in the latest frame; cleared at every new frame."""
        return self._at("world/camera/image/overlay")

    @property
    def shapes(self) -> str:
        return f"{self.overlay}/shapes"

    @property
    def image_pois(self) -> str:
        return f"{self.overlay}/pois"

    @property
    def match(self) -> str:
        return f"{self.overlay}/match"

    @property
    def photos(self) -> str:
        return self._at("world/photos")

    @property
    def pois(self) -> str:
        return self._at("world/pois")

    @property
    def viewpoints(self) -> str:
        return self._at("world/viewpoints")

    @property
    def footprint(self) -> str:
        return self._at("world/viewpoints/footprint")

    @property
    def model(self) -> str:
        return self._at("world/model")

    @property
    def model_mesh(self) -> str:
        return self._at("world/model/mesh")

    @property
    def target(self) -> str:
        """The target picture: one per recording (a fleet's vehicles look for one target)."""
        return self._shared("target")

    def picture(self, tag: str) -> str:
        """An image the mission made (a ``Picture`` output), by its tag."""
        return self._at(f"pictures/{rr_name(tag)}")

    @property
    def target_shapes(self) -> str:
        return self._shared("target/shapes")

    @property
    def plots(self) -> str:
        return self._at("plots")

    def telemetry(self, name: str) -> str:
        return self._at(f"plots/telemetry/{name}")

    @property
    def recognition(self) -> str:
        return self._at("plots/recognition")

    def recognition_poi(self, poi: int) -> str:
        return f"{self.recognition}/poi_{poi}"

    @property
    def threshold(self) -> str:
        return f"{self.recognition}/threshold"

    @property
    def log(self) -> str:
        return self._at("log")

    def log_source(self, source: str) -> str:
        """Text log of one source: ``mission``, ``vehicle`` (STATUSTEXT, mode), ``runner``."""
        return self._at(f"log/{source}")

    @property
    def map(self) -> str:
        return self._at("map")

    @property
    def map_vehicle(self) -> str:
        return self._at("map/vehicle")


@dataclass(frozen=True, slots=True)
class FleetVehicle:
    """One vehicle of a fleet's recording: its MAVLink system id and its home in the fleet's
    frame (ENU metres around vehicle 1's home), where its own frame is placed."""

    sysid: int
    home_en_m: tuple[float, float]

    @property
    def name(self) -> str:
        """Its part of the entity paths (``uav2``), as its topics' namespace (``/uav2``)."""
        return f"uav{self.sysid}"


def _safe(name: str) -> str:
    # Entity path parts are identifiers; scene names are free text.
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in name) or "_"


def rr_name(text: str) -> str:
    """``text`` as one entity-path part: letters, digits, ``-`` and ``_`` (others as ``_``)."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in text)[:64] or "_"
