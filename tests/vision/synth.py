"""Synthetic test images: flat-coloured polygons with slight shading and optional noise.

The shape families are distinct by construction (a rectangle, an L, a T, a U, a notched
pentagon and a trapezoid), so shapes of different families must not match.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
FAMILIES = ("rect", "L", "T", "U", "house", "trapezoid")

GREY = (128, 128, 128)


def family_shape(family: str, aspect: float, notch: float) -> FloatArray:
    """A unit-ish polygon (about 1 across) of a family; ``aspect`` in [0.5, 1], ``notch`` in
    [0.3, 0.5] sets the family's proportions."""
    w, h = 1.0, aspect
    t = notch  # arm thickness / notch size relative to the side
    if family == "rect":
        pts = [(0, 0), (w, 0), (w, h), (0, h)]
    elif family == "L":
        pts = [(0, 0), (w, 0), (w, t * h), (t * w, t * h), (t * w, h), (0, h)]
    elif family == "T":
        a, b = 0.5 - t / 2, 0.5 + t / 2
        pts = [(0, 0), (w, 0), (w, t * h), (b * w, t * h)]
        pts += [(b * w, h), (a * w, h), (a * w, t * h), (0, t * h)]
    elif family == "U":
        pts = [(0, 0), (w, 0), (w, h), ((1 - t) * w, h)]
        pts += [((1 - t) * w, t * h), (t * w, t * h), (t * w, h), (0, h)]
    elif family == "house":
        pts = [(0, 0), (w, 0), (w, h), (w / 2, h + 0.5 * h), (0, h)]
    elif family == "trapezoid":
        inset = 0.5 * t  # the top edge stays over half the base: not a near-triangle
        pts = [(0, 0), (w, 0), ((1 - inset) * w, h), (inset * w, h)]
    else:
        raise ValueError(family)
    arr = np.array(pts, dtype=np.float64)
    return arr - arr.mean(axis=0)


def place(
    poly: FloatArray, *, angle_deg: float, size_px: float, centre: tuple[float, float]
) -> FloatArray:
    """Rotate (clockwise on screen), scale and move a unit polygon into pixel coordinates."""
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)
    rot = np.array([[c, -s], [s, c]])
    return (poly @ rot.T) * size_px + np.array(centre)


def unit_point(
    point: tuple[float, float], *, angle_deg: float, size_px: float, centre: tuple[float, float]
) -> tuple[float, float]:
    """Where `place` puts a point of the unit polygon's frame."""
    u, v = place(
        np.array([point], dtype=np.float64), angle_deg=angle_deg, size_px=size_px, centre=centre
    )[0]
    return float(u), float(v)


def draw(
    polys: list[tuple[FloatArray, tuple[int, int, int]]],
    *,
    size: tuple[int, int] = (640, 480),
    noise_sigma: float = 0.0,
    seed: int = 0,
    holes: list[FloatArray] | None = None,
    shade: bool = True,
) -> npt.NDArray[np.uint8]:
    """An RGB image with grey ground and each polygon filled in its colour, the lower half
    of each polygon slightly darker (shading), holes filled with ground, optional noise."""
    w, h = size
    img = np.full((h, w, 3), GREY, dtype=np.uint8)
    for poly, colour in polys:
        pts = np.round(poly * 16).astype(np.int32)
        cv2.fillPoly(img, [pts], colour, lineType=cv2.LINE_8, shift=4)
        if not shade:
            continue
        shade = tuple(int(c * 0.85) for c in colour)
        mask = np.zeros((h, w), np.uint8)
        cv2.fillPoly(mask, [pts], 255, shift=4)
        cy = int(poly[:, 1].mean())
        mask[:cy] = 0
        img[mask > 0] = shade
    for hole in holes or []:
        cv2.fillPoly(img, [np.round(hole * 16).astype(np.int32)], GREY, shift=4)
    if noise_sigma > 0:
        rng = np.random.default_rng(seed)
        img = np.clip(img + rng.normal(0.0, noise_sigma, img.shape), 0, 255).astype(np.uint8)
    return img
