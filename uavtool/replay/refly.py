"""Re-fly: fly a recording's configuration again on the built-in vehicle, in lockstep, from
the recording's metadata alone, and compare the new recording with the old one.

Where ``replay --check`` proves the mission reproduces its outputs from recorded observations,
re-flying is the regression test for everything together: the vehicle, the link, the renderer
and the mission. A lockstep flight is a function of its inputs, so the new recording must hold
the same messages, in the same order, with the same times and bytes.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from itertools import zip_longest
from pathlib import Path
from typing import Any

from uavtool.errors import InputError
from uavtool.mission import Params
from uavtool.mission.params import from_dict
from uavtool.recording import CompressedImage, RecordingReader
from uavtool.recording.files import refuse_same_file
from uavtool.recording.reader import Message
from uavtool.recording.topics import TARGET
from uavtool.runner.fly import FlightSummary, FlyConfig, fly
from uavtool.runner.runner import Progress
from uavtool.sitl.lockstep import SIM_EPOCH_NS
from uavtool.world import scene_from_dict

# Metadata that names the software, not the flight: a re-flight by a newer version of the
# same code must still compare equal.
_VERSION_KEYS = {("uavtool", "version"), ("mission", "tool_version")}


class ReflyInputError(InputError):
    """The recording cannot be re-flown (not a lockstep flight of the built-in vehicle)."""


@dataclass(frozen=True, slots=True)
class ReflyResult:
    """``first_difference`` is None when the new recording equals the old one."""

    recording: Path
    reflown: Path
    messages: int
    first_difference: str | None
    summary: FlightSummary

    @property
    def identical(self) -> bool:
        return self.first_difference is None


def is_lockstep(path: Path) -> bool:
    """Whether ``path`` is a lockstep flight of the built-in vehicle (one that can be re-flown)."""
    with RecordingReader(path) as reader:
        meta = dict(reader.metadata)
    return meta.get("vehicle", {}).get("clock") == "lockstep" and "flight" in meta


def refly_config(path: Path, *, out: Path, workdir: Path) -> FlyConfig:
    """The :class:`FlyConfig` that made the lockstep recording ``path``, recording to ``out``
    (a target picture the user gave is written into ``workdir``). Raises ReflyInputError."""
    with RecordingReader(path) as reader:
        reader.require_metadata(("mission", "scene", "flight", "vehicle"))
        reader.require_intact()  # now, not after flying: the comparison needs all of it
        meta = dict(reader.metadata)
        vehicle = meta.get("vehicle", {})
        if not is_lockstep(path):
            raise ReflyInputError(
                f"{path}: not a lockstep flight of the built-in vehicle (metadata 'vehicle' "
                "clock is not 'lockstep'); only those can be flown again: make one with "
                "`uavtool fly`"
            )
        flight = meta["flight"]
        camera = vehicle.get("camera", "sim")
        if camera != "sim":
            # Anything else is a device or a URL for OpenCV/FFmpeg to open: never from a file.
            raise ReflyInputError(
                f"{path}: recorded with the camera {camera[:40]!r}; only a flight with the "
                "simulated camera can be flown again"
            )
        try:
            scene = scene_from_dict(json.loads(meta["scene"]["json"]), source=f"{path}: scene")
            params: Params = from_dict(
                json.loads(meta["mission"]["params"]), source=f"{path}: mission parameters"
            )
            wind = json.loads(flight["wind"])
            config = FlyConfig(
                scene=scene,
                camera="sim",
                record=out,
                params=params,
                vehicle_params=tuple(
                    (str(n), float(v)) for n, v in json.loads(flight["vehicle_params"])
                ),
                seed=int(flight["seed"]),
                noise=bool(json.loads(flight["noise"])),
                wind=(float(wind[0]), float(wind[1])),
                link_outages_s=tuple(
                    (float(a), float(d)) for a, d in json.loads(flight["link_outages_s"])
                ),
                hfov_deg=float(json.loads(flight["hfov_deg"])),
                size_px=_size_px(json.loads(flight["size_px"])),
                target=_target_file(reader, path, workdir) if flight["target"] == "file" else None,
                no_gimbal=json.loads(flight.get("no_gimbal", "false")) is True,
            )
        except (KeyError, ValueError, TypeError, IndexError) as exc:
            raise ReflyInputError(
                f"{path}: metadata 'flight' is incomplete or unreadable ({exc!r}); "
                "the recording cannot be flown again"
            ) from None
    return config


_SIDE_PX = (16, 8192)
"""The image sides a re-flight accepts (as ``uavtool scene --size``): a recording asking for
more is refused before anything is allocated."""


def _size_px(value: object) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise ValueError(f"size_px {value!r} is not [width, height]")
    w, h = (int(v) for v in value)
    lo, hi = _SIDE_PX
    if not (lo <= w <= hi and lo <= h <= hi):
        raise ValueError(f"size_px {w}x{h} is outside {lo}..{hi} pixels a side")
    return w, h


def refly(
    path: str | Path,
    *,
    out: Path | None = None,
    progress: Progress | None = None,
    compare: bool = True,
) -> ReflyResult:
    """Fly ``path``'s configuration again (to ``out``, or a temporary file that is removed)
    and compare the two recordings message by message."""
    path = Path(path)
    if out is not None:
        refuse_same_file(out, [path])
    with tempfile.TemporaryDirectory(prefix="uavtool-refly-") as tmp:
        work = Path(tmp)
        target = out if out is not None else work / "reflown.mcap"
        summary = fly(refly_config(path, out=target, workdir=work), progress=progress)
        count, diff = compare_recordings(path, target) if compare else (0, None)
    return ReflyResult(path, target, count, diff, summary)


def compare_recordings(old: Path, new: Path) -> tuple[int, str | None]:
    """(messages compared, the first difference in words or None) between two recordings:
    metadata records (software versions aside), then every message in file order — topic,
    log and publish time, sequence and bytes. The MCAP header, which names library versions,
    is not compared."""
    with RecordingReader(old) as a, RecordingReader(new) as b:
        diff = _metadata_difference(a.metadata, b.metadata)
        if diff is not None:
            return 0, diff
        count = 0
        for was, now in zip_longest(a.messages(), b.messages()):
            if was is None or now is None:
                which, extra = ("re-flown", now) if was is None else ("recorded", was)
                assert extra is not None
                return count, f"the {which} flight has more messages, from {_where(count, extra)}"
            diff = _message_difference(was, now)
            if diff is not None:
                return count, f"{_where(count, was)}: {diff}"
            count += 1
    return count, None


def _where(index: int, m: Message) -> str:
    t = (m.log_time_ns - SIM_EPOCH_NS) / 1e9
    return f"message {index} ({m.channel.topic}, vehicle time {t:.3f} s)"


def _message_difference(was: Message, now: Message) -> str | None:
    checks: list[tuple[str, Callable[[Message], Any]]] = [
        ("topic", lambda m: m.channel.topic),
        ("log_time", lambda m: m.log_time_ns),
        ("publish_time", lambda m: m.publish_time_ns),
        ("sequence", lambda m: m.sequence),
    ]
    for name, get in checks:
        if get(was) != get(now):
            return f"{name} {get(was)!r} recorded, {get(now)!r} re-flown"
    if was.data == now.data:
        return None
    if was.channel.message_encoding == "json":
        return _json_difference(json.loads(was.data), json.loads(now.data))
    offset = next(i for i, (x, y) in enumerate(zip_longest(was.data, now.data)) if x != y)
    return f"bytes differ from offset {offset} ({len(was.data)} recorded, {len(now.data)} re-flown)"


def _json_difference(was: Any, now: Any, where: str = "") -> str:
    if isinstance(was, dict) and isinstance(now, dict):
        for key in sorted(set(was) | set(now)):
            if was.get(key) != now.get(key):
                return _json_difference(was.get(key), now.get(key), f"{where}.{key}")
    if isinstance(was, list) and isinstance(now, list) and len(was) == len(now):
        for i, (x, y) in enumerate(zip(was, now, strict=True)):
            if x != y:
                return _json_difference(x, y, f"{where}[{i}]")
    return f"{where.lstrip('.') or 'value'}: {_short(was)} recorded, {_short(now)} re-flown"


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _metadata_difference(
    was: list[tuple[str, dict[str, str]]], now: list[tuple[str, dict[str, str]]]
) -> str | None:
    def comparable(records: list[tuple[str, dict[str, str]]]) -> list[tuple[str, dict[str, str]]]:
        return [
            (name, {k: v for k, v in rec.items() if (name, k) not in _VERSION_KEYS})
            for name, rec in records
        ]

    a, b = comparable(was), comparable(now)
    if [n for n, _ in a] != [n for n, _ in b]:
        return f"metadata records {[n for n, _ in a]} recorded, {[n for n, _ in b]} re-flown"
    for (name, x), (_, y) in zip(a, b, strict=True):
        if x != y:
            key = next(k for k in sorted(set(x) | set(y)) if x.get(k) != y.get(k))
            try:  # a JSON value (the parameters): name the field inside it
                inner = _json_difference(json.loads(x[key]), json.loads(y[key]))
            except (KeyError, TypeError, ValueError):
                inner = f"{_short(x.get(key))} recorded, {_short(y.get(key))} re-flown"
            return f"metadata {name}.{key}: {inner}"
    return None


def _target_file(reader: RecordingReader, path: Path, workdir: Path) -> Path:
    for entry in reader.entries([TARGET]):
        if isinstance(entry.value, CompressedImage):
            file = workdir / "target.png"
            file.write_bytes(entry.value.data)
            return file
    raise ReflyInputError(f"{path}: the target picture ({TARGET}) is missing")
