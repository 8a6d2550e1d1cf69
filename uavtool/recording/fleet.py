"""A fleet in one recording: each vehicle's topics under a namespace of its own.

Vehicle with system id ``k`` writes every topic of a one-vehicle recording under ``/uavK``
(``/uav2/mission/observations``, ``/uav2/camera/image``, ``/uav2/vehicle/fix`` …), as ROS and
Foxglove users namespace a robot's topics; the MAVLink channels stay shared (``/mavlink/…``),
every vehicle's frames on them told apart by their system id, as on a radio that carries a
fleet (MAVProxy's tlog of several vehicles is the same). The target picture and the fleet's
outcome are the fleet's own, at the top level.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from uavtool.geo import GeoPoint, geo_from_enu
from uavtool.recording.topics import FIX, POSE
from uavtool.recording.values import LocationFix, Pose, PosesInFrame

if TYPE_CHECKING:
    from uavtool.recording.foxglove import FoxgloveValue
    from uavtool.recording.protocol import MessageWriter
    from uavtool.recording.values import Direction

FLEET_METADATA = "fleet"
"""The flight description's record of a fleet (``vehicles``, ``offset_line``): present only
in a fleet's recording."""
CREW_METADATA = "crew"
"""The metadata record of what the fleet mission was given besides the flight's description:
``homes_en_m``, each vehicle's home in the fleet's frame (JSON ``[[east, north], …]``)."""

_PREFIX = re.compile(r"^/uav([1-9][0-9]{0,2})(/.*)$")


def vehicle_prefix(sysid: int) -> str:
    """The namespace of vehicle ``sysid``'s topics: ``/uav2``."""
    return f"/uav{sysid}"


def split_topic(topic: str) -> tuple[int | None, str]:
    """``/uav2/camera/image`` → (2, ``/camera/image``); a topic of no vehicle → (None, it)."""
    m = _PREFIX.match(topic)
    if m is None:
        return None, topic
    return int(m.group(1)), m.group(2)


def outcome_name(sysid: int) -> str:
    """The metadata record of vehicle ``sysid``'s outcome (the fleet's is ``outcome``)."""
    return f"outcome.uav{sysid}"


class VehicleWriter:
    """One vehicle's view of a fleet's writer: its topics under :func:`vehicle_prefix`, its
    outcome under :func:`outcome_name`, its MAVLink on the shared channels."""

    def __init__(self, writer: MessageWriter, sysid: int) -> None:
        self.writer = writer
        self.sysid = sysid
        self.prefix = vehicle_prefix(sysid)

    def add_metadata(self, name: str, record: Mapping[str, str]) -> None:
        self.writer.add_metadata(outcome_name(self.sysid) if name == "outcome" else name, record)

    def add_json_topic(self, topic: str, *, schema_name: str, schema: Mapping[str, Any]) -> None:
        self.writer.add_json_topic(self.prefix + topic, schema_name=schema_name, schema=schema)

    def write_json(
        self,
        topic: str,
        payload: Mapping[str, Any],
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        self.writer.write_json(
            self.prefix + topic, payload, log_time_ns=log_time_ns, publish_time_ns=publish_time_ns
        )

    def write_json_bytes(
        self, topic: str, data: bytes, *, log_time_ns: int, publish_time_ns: int | None = None
    ) -> None:
        self.writer.write_json_bytes(
            self.prefix + topic, data, log_time_ns=log_time_ns, publish_time_ns=publish_time_ns
        )

    def write_json_format(
        self, topic: str, template: str, values: tuple[Any, ...], *, log_time_ns: int
    ) -> None:
        self.writer.write_json_format(
            self.prefix + topic, template, values, log_time_ns=log_time_ns
        )

    def write(
        self,
        topic: str,
        value: FoxgloveValue,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None:
        self.writer.write(
            self.prefix + topic, value, log_time_ns=log_time_ns, publish_time_ns=publish_time_ns
        )

    def write_mavlink(
        self,
        frame: bytes,
        *,
        direction: Direction,
        log_time_ns: int,
        publish_time_ns: int | None = None,
        decoded: Any = None,
    ) -> None:
        self.writer.write_mavlink(
            frame,
            direction=direction,
            log_time_ns=log_time_ns,
            publish_time_ns=publish_time_ns,
            decoded=decoded,
        )

    def hand_off(self) -> None:
        self.writer.hand_off()

    def mavlink_tap(
        self, clock_ns: Callable[[], int]
    ) -> Callable[[str, list[bytes], list[Any] | None], None]:
        return self.writer.mavlink_tap(clock_ns)

    def write_vehicle(
        self,
        pos_enu_m: tuple[float, float, float],
        heading_deg: float,
        origin: GeoPoint | None,
        *,
        log_time_ns: int,
    ) -> None:
        """As the writer's: the pose (in the vehicle's own frame) and, with ``origin``, the
        WGS-84 fix, under this vehicle's namespace."""
        pose = PosesInFrame((Pose.from_enu_heading(pos_enu_m, heading_deg),))
        self.write(POSE, pose, log_time_ns=log_time_ns)
        if origin is not None:
            geo = geo_from_enu(origin, *pos_enu_m)
            fix = LocationFix(geo.lat_deg, geo.lon_deg, geo.alt_amsl_m)
            self.write(FIX, fix, log_time_ns=log_time_ns)

    def close(self) -> None:
        """The fleet's writer is closed by the fleet, not by one vehicle."""
