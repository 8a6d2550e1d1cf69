"""`uavtool.png`: frames as PNG, read back by libpng (through OpenCV) pixel for pixel, with
every chunk's CRC and the zlib stream checked."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from uavtool.images import png_decode, png_encode
from uavtool.png import rgb_png


def _chunks(png: bytes) -> list[tuple[bytes, bytes]]:
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    chunks, pos = [], 8
    while pos < len(png):
        (length,) = struct.unpack_from(">I", png, pos)
        kind, body = png[pos + 4 : pos + 8], png[pos + 8 : pos + 8 + length]
        (crc,) = struct.unpack_from(">I", png, pos + 8 + length)
        assert crc == zlib.crc32(kind + body), kind
        chunks.append((kind, body))
        pos += 12 + length
    assert pos == len(png)
    return chunks


@pytest.mark.parametrize(("height", "width"), [(1, 1), (2, 3), (7, 1), (1, 9), (480, 640)])
def test_libpng_reads_back_the_very_pixels(height: int, width: int) -> None:
    rng = np.random.default_rng(height * 1000 + width)
    noise = rng.integers(0, 256, size=(height, width, 3), dtype=np.uint8)
    flat = np.zeros_like(noise)
    flat[: height // 2] = (200, 30, 90)  # what rendered frames are like: flat colours
    for rgb in (noise, flat):
        png = rgb_png(rgb.tobytes(), height, width)
        assert np.array_equal(png_decode(png), rgb)
        assert png_encode(rgb) == png
        assert np.array_equal(png_decode(png_encode(rgb[:, ::-1])), rgb[:, ::-1])  # a view


def test_the_layout_is_one_header_one_data_chunk_and_the_end() -> None:
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    chunks = _chunks(rgb_png(rgb.tobytes(), 2, 3))
    assert [kind for kind, _ in chunks] == [b"IHDR", b"IDAT", b"IEND"]
    # 3 wide, 2 high, 8 bits a channel, truecolour, deflate, adaptive filtering, no interlace
    assert chunks[0][1] == struct.pack(">IIBBBBB", 3, 2, 8, 2, 0, 0, 0)
    rows = zlib.decompress(chunks[1][1])
    assert rows == b"\x00" + rgb[0].tobytes() + b"\x00" + rgb[1].tobytes()  # unfiltered rows
    assert chunks[2][1] == b""


@pytest.mark.parametrize(
    ("pixels", "height", "width", "problem"),
    [
        (b"\x00" * 9, 1, 2, "are 6 bytes, not 9"),
        (b"", 0, 4, "sides are 1 to"),
        (b"", 4, 0, "sides are 1 to"),
        (b"\x00" * 3, 1, 2**31, "sides are 1 to"),
    ],
)
def test_pixels_that_do_not_make_the_image_say_why(
    pixels: bytes, height: int, width: int, problem: str
) -> None:
    with pytest.raises(ValueError, match=problem):
        rgb_png(pixels, height, width)


@pytest.mark.parametrize(
    "array",
    [np.zeros((4, 4), np.uint8), np.zeros((4, 4, 4), np.uint8), np.zeros((4, 4, 3), np.uint16)],
)
def test_png_encode_takes_rgb_bytes_only(array: np.ndarray) -> None:
    with pytest.raises(ValueError, match=r"takes \(H, W, 3\) uint8 RGB"):
        png_encode(array)
