"""``uavtool export REC --model FILE.glb --target FILE.png``: the built model and the target
picture out of a recording, byte for byte as recorded (``/mission/model``'s last GLB,
``/mission/target``'s PNG). Each output appears only once complete."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from uavtool.recording.errors import RecordingError
from uavtool.recording.files import atomic_output
from uavtool.recording.fleet import split_topic
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import MODEL, TARGET
from uavtool.recording.values import CompressedImage, Model3D


def export_model(rec: str | Path, out: str | Path) -> int:
    """Write the last model ``rec`` holds (a GLB) to ``out``; its size in bytes (a fleet's:
    whichever vehicle built it). Raises `RecordingError` when the flight built no model."""
    return _export(
        rec,
        out,
        MODEL,
        lambda v: v.glb if isinstance(v, Model3D) and v.glb else None,
        "holds no built model (/mission/model): its flight built none",
    )


def export_target(rec: str | Path, out: str | Path) -> int:
    """Write the recording's target picture (a PNG) to ``out``; its size in bytes. Raises
    `RecordingError` when it holds none."""
    return _export(
        rec,
        out,
        TARGET,
        lambda v: v.data if isinstance(v, CompressedImage) and v.data else None,
        "holds no target picture (/mission/target)",
    )


def _export(
    rec: str | Path,
    out: str | Path,
    topic: str,
    pick: Callable[[object], bytes | None],
    missing: str,
) -> int:
    data = _last(rec, topic, pick, missing)
    with atomic_output(out, inputs=[rec]) as tmp:
        _write(tmp, data, out)
    return len(data)


def _last(
    rec: str | Path, topic: str, pick: Callable[[object], bytes | None], missing: str
) -> bytes:
    found: bytes | None = None
    with RecordingReader(rec) as reader:
        # the topic, or a fleet's vehicles' (/uavK + topic), in the order they were written
        topics = [t for t in reader.topics() if split_topic(t)[1] == topic]
        if topics:
            for entry in reader.entries(topics):
                data = pick(entry.value)
                if data is not None:
                    found = data
    if found is None:
        raise RecordingError(rec, missing)
    return found


def _write(tmp: Path, data: bytes, out: str | Path) -> None:
    try:
        tmp.write_bytes(data)
    except OSError as exc:
        raise RecordingError(Path(out), f"cannot write: {exc.strerror or exc}") from None
