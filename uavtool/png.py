"""RGB pixels as PNG (https://www.w3.org/TR/png-3/): what recordings hold for camera frames,
and what :func:`uavtool.images.png_encode` writes.

Written here with zlib alone: a truecolour image, 8 bits a channel, no interlace, every row
unfiltered, one IDAT chunk, deflated at level 3. For the rendered frames a flight records
this is as fast as OpenCV's libpng with its quickest settings and as small, and a
recording's writer process then imports neither OpenCV nor numpy (~0.37 G instructions a
flight, beside the flight).
"""

from __future__ import annotations

import struct
import zlib

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_LEVEL = 3  # zlib's: level 6 makes a frame ~45 % smaller and takes ~2.4x as long
_MAX_SIDE = 2**31 - 1  # PNG's own limit on a side


def rgb_png(pixels: bytes | bytearray | memoryview, height_px: int, width_px: int) -> bytes:
    """``height_px`` rows of ``width_px`` RGB pixels (3 bytes each, row after row) as PNG.

    Raises ValueError when a side is not in 1 .. 2**31 - 1 or ``pixels`` is not exactly
    ``height_px * width_px * 3`` bytes."""
    if not (0 < height_px <= _MAX_SIDE and 0 < width_px <= _MAX_SIDE):
        raise ValueError(f"a PNG's sides are 1 to {_MAX_SIDE} pixels, not {width_px}x{height_px}")
    data = memoryview(pixels).cast("B")
    stride = 3 * width_px
    if len(data) != height_px * stride:
        raise ValueError(
            f"{width_px}x{height_px} RGB pixels are {height_px * stride} bytes, not {len(data)}"
        )
    deflate = zlib.compressobj(_LEVEL)
    none = b"\x00"  # each row's filter: None
    parts = [deflate.compress(none + data[i : i + stride]) for i in range(0, len(data), stride)]
    parts.append(deflate.flush())
    header = struct.pack(">IIBBBBB", width_px, height_px, 8, 2, 0, 0, 0)
    chunks = (_chunk(b"IHDR", header), _chunk(b"IDAT", b"".join(parts)), _chunk(b"IEND", b""))
    return _SIGNATURE + b"".join(chunks)


def _chunk(kind: bytes, body: bytes) -> bytes:
    crc = zlib.crc32(body, zlib.crc32(kind))
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)
