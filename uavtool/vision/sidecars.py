"""The photos and poses ``uavtool export --frames`` writes, as ``uavtool vision model`` reads
them: each ``frame_NNNN.png`` beside its ``frame_NNNN.json`` sidecar (``pose``, ``intrinsics``,
and the mission's ``tag``), so that a flight's top, front and right photos model again without
a poses file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from uavtool.vision.errors import ShapeFileError
from uavtool.vision.io import VIEW_NAMES


def sidecar_of(image: Path) -> Path:
    """``frame_0006.png`` -> ``frame_0006.json``."""
    return image.with_suffix(".json")


def poses_from_sidecars(images: dict[str, Path]) -> str:
    """A poses document (:func:`uavtool.vision.io.views_from_json`) from each image's
    sidecar; raises ShapeFileError naming the sidecar that is missing or lacks a pose."""
    doc: dict[str, Any] = {"ground_z_m": 0.0}
    for name, image in images.items():
        record = _read(sidecar_of(image))
        pose, intrinsics = record.get("pose"), record.get("intrinsics")
        if not isinstance(pose, dict) or not isinstance(intrinsics, dict):
            raise ShapeFileError(
                f"{sidecar_of(image)}: no pose and intrinsics for the {name} photo (a "
                "sidecar of uavtool export --frames holds both; or give --poses FILE)"
            )
        doc[name] = {**{k: v for k, v in pose.items() if k != "type"}, "intrinsics": intrinsics}
    return json.dumps(doc)


def views_in_folder(folder: Path) -> dict[str, Path]:
    """The top, front and right photos of a folder ``uavtool export --frames`` wrote: for each,
    the last frame whose sidecar has that tag. Raises ShapeFileError naming what is missing."""
    found: dict[str, Path] = {}
    for sidecar in sorted(folder.glob("frame_*.json")):
        tag = _read(sidecar).get("tag")
        image = sidecar.with_suffix(".png")
        if tag in VIEW_NAMES and image.is_file():
            found[str(tag)] = image
    missing = [name for name in VIEW_NAMES if name not in found]
    if missing:
        raise ShapeFileError(
            f"{folder}: no frame tagged {', '.join(missing)} (a folder of uavtool export "
            "--frames of a flight that photographed its target from the top, front and right)"
        )
    return {name: found[name] for name in VIEW_NAMES}


def _read(path: Path) -> dict[str, Any]:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ShapeFileError(
            f"{path}: no such sidecar (uavtool export --frames writes one beside each "
            "frame; or give --poses FILE)"
        ) from None
    except OSError as exc:
        raise ShapeFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise ShapeFileError(f"{path}: not a JSON sidecar") from None
    if not isinstance(doc, dict):
        raise ShapeFileError(f"{path}: not a JSON object")
    return doc
