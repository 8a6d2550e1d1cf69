"""Decoding images from users: corrupt, empty and oversized images are refused on one line,
before a pixel is allocated."""

from __future__ import annotations

import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from tests.cli.bad_inputs import BAD_IMAGES, _jpeg_header, _png
from uavtool.errors import InputError
from uavtool.images import declared_size, png_decode, png_encode, read_image


def test_round_trip_is_lossless() -> None:
    rgb = np.random.default_rng(0).integers(0, 256, (12, 20, 3), dtype=np.uint8)
    data = png_encode(rgb)
    assert declared_size(data) == (20, 12)
    assert np.array_equal(png_decode(data), rgb)


def test_decoding_swaps_the_channels_as_numpy_does() -> None:
    # png_decode swaps OpenCV's blue-green-red with OpenCV (~70x faster than numpy's copy of a
    # reversed view): the same pixels, in a contiguous array; png_encode takes any view
    import cv2

    rng = np.random.default_rng(7)
    for rgb in (
        rng.integers(0, 256, (48, 64, 3), dtype=np.uint8),
        rng.integers(0, 256, (60, 90, 3), dtype=np.uint8)[5:50:2, 3:80:3],  # a strided view
    ):
        data = png_encode(rgb)
        assert data == png_encode(np.ascontiguousarray(rgb))
        bgr = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
        decoded = png_decode(data)
        assert decoded.flags["C_CONTIGUOUS"] and np.array_equal(decoded, bgr[:, :, ::-1])
        assert np.array_equal(decoded, rgb)


def test_headers_give_the_size() -> None:
    assert declared_size(_png(100_000, 3)) == (100_000, 3)
    assert declared_size(_jpeg_header(640, 480)) == (640, 480)
    assert declared_size(b"GIF89a") is None


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("empty.png", "t: empty, not an image"),
        ("huge.png", "t: image of 100000×100000 pixels is larger than 8192×8192"),
        ("wide.png", "t: image of 30000×2 pixels is larger than 8192×8192"),
        ("huge.jpg", "t: image of 60000×60000 pixels is larger than 8192×8192"),
        ("garbage.png", "t: not a decodable image (108 bytes)"),
        ("text.png", "t: not a decodable image (20 bytes)"),
    ],
)
def test_bad_images_are_refused_cheaply(name: str, message: str) -> None:
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(InputError) as info:
            png_decode(BAD_IMAGES[name], where="t")
    finally:
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    assert str(info.value) == message
    assert peak < 10e6 and time.perf_counter() - t0 < 1.0


def test_files_name_the_problem(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such image file"):
        read_image(tmp_path / "missing.png")
    with pytest.raises(InputError, match="is a directory, not an image"):
        read_image(tmp_path)
