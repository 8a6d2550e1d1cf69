"""What writing a recording offers and checks, without the writing: the `MessageWriter`
protocol that `RecordingWriter` and `ProcessWriter` both meet, and the checks of arguments
both make. A flight that writes in a process of its own imports this, not the MCAP writer."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from functools import cache
from types import ModuleType
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from uavtool.geo import GeoPoint
    from uavtool.recording.foxglove import FoxgloveValue
    from uavtool.recording.values import Direction

TOOL_METADATA = "uavtool"  # name of the metadata record the writer adds itself


@cache
def foxglove_module() -> ModuleType:
    """`uavtool.recording.foxglove`, imported when first needed: a writer that is given no
    Foxglove value (a telemetry log's import, say) needs none of Foxglove's modules."""
    return importlib.import_module("uavtool.recording.foxglove")


class MessageWriter(Protocol):
    """What a flight's recorder needs of a writer: `RecordingWriter`, or the same in a
    process of its own (`uavtool.recording.process.ProcessWriter`)."""

    def add_metadata(self, name: str, record: Mapping[str, str]) -> None: ...

    def hand_off(self) -> None:
        """Start on what is held now, without waiting (a writer process writes it while the
        flight's process does other work); a writer that holds nothing back does nothing."""
        ...

    def add_json_topic(
        self, topic: str, *, schema_name: str, schema: Mapping[str, Any]
    ) -> None: ...

    def write_json(
        self,
        topic: str,
        payload: Mapping[str, Any],
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None: ...

    def write_json_bytes(
        self, topic: str, data: bytes, *, log_time_ns: int, publish_time_ns: int | None = None
    ) -> None: ...

    def write_json_format(
        self, topic: str, template: str, values: tuple[Any, ...], *, log_time_ns: int
    ) -> None:
        """`write_json_bytes` of ``(template % values).encode()``: the caller vouches that it
        is JSON as `dumps` writes it; a writer process formats it, off the flight's path."""
        ...

    def write(
        self,
        topic: str,
        value: FoxgloveValue,
        *,
        log_time_ns: int,
        publish_time_ns: int | None = None,
    ) -> None: ...

    def write_mavlink(
        self,
        frame: bytes,
        *,
        direction: Direction,
        log_time_ns: int,
        publish_time_ns: int | None = None,
        decoded: Any = None,
    ) -> None: ...

    def mavlink_tap(
        self, clock_ns: Callable[[], int]
    ) -> Callable[[str, list[bytes], list[Any] | None], None]:
        """A link's tap (``("in" | "out", frames, decoded messages or None)``, once per read
        or send) that writes each frame as `write_mavlink` does, all of one call stamped with
        one ``clock_ns()``: the same file, made with less work per frame (a flight taps tens
        of thousands)."""
        ...

    def write_vehicle(
        self,
        pos_enu_m: tuple[float, float, float],
        heading_deg: float,
        origin: GeoPoint | None,
        *,
        log_time_ns: int,
    ) -> None: ...

    def close(self) -> None: ...


def check_topic(topic: str) -> None:
    """`ValueError` unless ``topic`` may be written with `RecordingWriter.write` or a JSON
    topic."""
    if not topic.startswith("/") or topic.startswith("/mavlink/"):
        raise ValueError(f"topic {topic!r}: must start with '/' and not with '/mavlink/'")


def check_metadata(name: str, record: Mapping[str, str]) -> None:
    """`ValueError` unless ``record`` may be written as metadata named ``name``."""
    if name == TOOL_METADATA:
        raise ValueError(f"metadata name {name!r} is reserved for the writer")
    if not all(isinstance(k, str) and isinstance(v, str) for k, v in record.items()):
        raise ValueError(f"metadata {name!r}: keys and values must be str")
