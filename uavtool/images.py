"""In-memory PNG encoding of RGB frames (lossless; fast settings) — what recordings hold."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from uavtool.errors import InputError

U8Array = npt.NDArray[np.uint8]


def png_encode(rgb: U8Array) -> bytes:
    """(H, W, 3) uint8 RGB → PNG bytes. No adaptive filtering: ~3× faster, nearly as small."""
    import cv2  # noqa: PLC0415 - keep importing uavtool light

    params = [cv2.IMWRITE_PNG_COMPRESSION, 3, cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_SUB]
    ok, buf = cv2.imencode(".png", np.ascontiguousarray(rgb[:, :, ::-1]), params)
    if not ok:
        raise ValueError("PNG encoding failed")
    return bytes(buf)


def png_decode(data: bytes, *, where: str = "image") -> U8Array:
    """PNG (or any image OpenCV reads) bytes → (H, W, 3) uint8 RGB; InputError if corrupt."""
    import cv2  # noqa: PLC0415

    bgr = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), cv2.IMREAD_COLOR)
    if bgr is None:
        raise InputError(f"{where}: not a decodable image ({len(data)} bytes)")
    return np.ascontiguousarray(bgr[:, :, ::-1])
