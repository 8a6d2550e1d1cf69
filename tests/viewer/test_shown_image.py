"""The check behind the Lichtblick app test's image panels (`shown_image`), tested without
Lichtblick: panels drawn here as its image panel draws a picture (fitted whole and centred in
the canvas below the panel's toolbar, on its background, the panel's border over the edge)
pass with the picture they show and fail with another picture of the golden recordings: an
earlier frame of the same flight (a stale frame), another flight's last frame, the target
picture in the camera's panel and the camera's frame in the target's (a swapped topic), or
nothing drawn."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from tests.viewer.shown_image import MAX_ERROR, image_area, shown_error
from uavtool.recording.fleet import split_topic
from uavtool.recording.reader import RecordingReader
from uavtool.recording.topics import IMAGE, TARGET
from uavtool.recording.values import CompressedImage

GOLDEN = sorted((Path(__file__).parents[2] / "recordings" / "golden").glob("*.mcap"))
# Canvas boxes (x, y, width, height in the panel's screenshot): the layout's image panels in
# Lichtblick's app at 1600 × 1000 (the picture spans the width), and a wide one (the height).
CANVASES = {"layout": (0.0, 32.0, 288.0, 260.0), "wide": (0.0, 32.0, 600.0, 260.0)}
_BACKGROUND = (244, 244, 245)
_BORDER = (214, 214, 214)
SAME = 1.0
"""Pictures closer than this at full size are the same view (the paper goldens end at the same
pose: their last frames differ by at most 0.11)."""


def _pictures(recording: Path) -> tuple[list[np.ndarray], np.ndarray]:
    """The recording's camera frames, in order, and its target picture (RGB)."""
    frames: list[np.ndarray] = []
    target = None
    with RecordingReader(recording) as reader:
        # a fleet's frames are its vehicles' (/uavK/camera/image)
        images = sorted(
            {c.topic for c in reader.channels.values() if split_topic(c.topic)[1] == IMAGE}
        )
        for entry in reader.entries([*images, TARGET]):
            if isinstance(entry.value, CompressedImage):
                data = np.frombuffer(entry.value.data, np.uint8)
                rgb = cv2.imdecode(data, cv2.IMREAD_COLOR)[:, :, ::-1]
                if entry.topic != TARGET:
                    frames.append(rgb)
                else:
                    target = rgb
    assert frames and target is not None
    return frames, target


ALL = {p.stem: _pictures(p) for p in GOLDEN}


def _panel(picture: np.ndarray, canvas: tuple[float, float, float, float]) -> np.ndarray:
    """A screenshot of an image panel showing ``picture``, drawn as Lichtblick draws it (with
    another resampling than the check's)."""
    x, y, w, h = (round(v) for v in canvas)
    panel = np.full((y + h + 1, x + w, 3), _BACKGROUND, np.uint8)
    panel[: y - 2] = 255  # the toolbar, with a title
    panel[10:20, 8:90] = 60
    left, top, right, bottom = image_area(canvas, picture.shape[1], picture.shape[0])
    panel[top:bottom, left:right] = cv2.resize(
        picture, (right - left, bottom - top), interpolation=cv2.INTER_AREA
    )
    panel[[0, -1]], panel[:, [0, -1]] = _BORDER, _BORDER
    return panel.astype(np.int32)


def _different(picture: np.ndarray, other: np.ndarray) -> bool:
    return bool(np.abs(picture.astype(np.int32) - other.astype(np.int32)).mean() > SAME)


def test_the_fitted_area_is_where_lichtblick_draws_the_picture() -> None:
    # Measured in Lichtblick's app: a 640 × 480 frame in a 288 × 260 canvas fills rows 54-269.
    assert image_area(CANVASES["layout"], 640, 480) == (0, 54, 288, 270)
    assert image_area(CANVASES["wide"], 640, 480) == (127, 32, 473, 292)
    assert shown_error(np.zeros((100, 100, 3), np.int32), (0, 32, 288, 260), ALL["paper"][1]) == (
        float("inf")
    )


@pytest.mark.parametrize("canvas", CANVASES.values(), ids=CANVASES.keys())
@pytest.mark.parametrize("golden", ALL, ids=ALL.keys())
def test_a_panel_passes_with_its_picture_and_fails_with_any_other(
    golden: str, canvas: tuple[float, float, float, float]
) -> None:
    frames, target = ALL[golden]
    last_frames = [other[-1] for other, _ in ALL.values()]
    # The camera's panel, at the end of the flight: its last frame; not an earlier one (stale),
    # another flight's last one, or the target picture (swapped).
    camera = _panel(frames[-1], canvas)
    assert shown_error(camera, canvas, frames[-1]) < MAX_ERROR
    wrong = [p for p in [*frames, *last_frames, target] if _different(p, frames[-1])]
    assert len(wrong) >= len(frames)  # the earlier frames and the target at least
    errors = [shown_error(camera, canvas, p) for p in wrong]
    assert min(errors) >= MAX_ERROR, sorted(errors)[:3]
    # The target's panel: the target picture, not the camera's frame (swapped). (A photo the
    # flight took of the target from the picture's own viewpoint is nearly the picture: as
    # close as 2.8 at full size, and not what a swapped topic shows at the end of the flight.)
    shown = _panel(target, canvas)
    assert shown_error(shown, canvas, target) < MAX_ERROR
    errors = [shown_error(shown, canvas, p) for p in last_frames]
    assert min(errors) >= MAX_ERROR, sorted(errors)[:3]
    # Nothing drawn (the panel still empty): fails too.
    empty = _panel(np.full_like(target, _BACKGROUND), canvas)
    assert shown_error(empty, canvas, frames[-1]) >= MAX_ERROR
    assert shown_error(empty, canvas, target) >= MAX_ERROR
