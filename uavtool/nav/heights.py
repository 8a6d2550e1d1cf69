"""Roof heights from nadir photos, and the altitudes that follow from them.

Two photos of one roof from different camera positions tell its height twice over:

* by its size: a roof at height ``h`` seen straight down from altitude ``a`` by a camera of
  focal length ``f`` (pixels) spans ``f · W / (a − h)`` pixels for a roof ``W`` metres wide, so
  ``s1 · (a1 − h) = s2 · (a2 − h)`` and ``h = (s2 · a2 − s1 · a1) / (s2 − s1)``, with ``s`` the
  square root of its area in pixels (the outline's pixel error limits it to about 1 %);
* by triangulation: the rays through the roof's centroid from both cameras meet at the roof,
  ``P1 + (a1 − h) · v1 = P2 + (a2 − h) · v2`` with ``v`` a ray's horizontal run per metre of
  descent; least squares gives ``h``. A centroid averages thousands of pixels, so this is
  the sharper estimate — except for a roof straight below, whose rays barely differ.

:func:`roof_from_photos` weighs both by their expected errors. Heights are metres above
home, as the altitudes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import numpy.typing as npt

from uavtool.camera import CameraPose, Intrinsics, project

SIZE_ERROR = 0.01
"""Relative error of a roof's linear size in pixels (its outline's area, square-rooted)."""
CENTROID_ERROR_PX = 0.5
"""Error of a roof's centroid in pixels."""


def roof_height_m(
    *, area1_px: float, alt1_m: float, area2_px: float, alt2_m: float, min_ratio: float = 1.05
) -> float | None:
    """The roof height of one building seen whole in two nadir photos from ``alt1_m`` and
    ``alt2_m`` (its outline's area in each, square pixels). None when the two sizes differ by
    less than ``min_ratio`` (the altitudes are too close for the sizes to tell), when the
    roof is not larger from the lower camera (from one altitude, sizes tell nothing) or the
    result is not below both cameras."""
    if area1_px <= 0.0 or area2_px <= 0.0:
        return None
    s1, s2 = math.sqrt(area1_px), math.sqrt(area2_px)
    if max(s1, s2) < min_ratio * min(s1, s2) or (s2 - s1) * (alt1_m - alt2_m) <= 0.0:
        return None
    h = (s2 * alt2_m - s1 * alt1_m) / (s2 - s1)
    if not math.isfinite(h) or h >= min(alt1_m, alt2_m):
        return None
    return h


def fit_altitude_m(*, roof_m: float, extent_m: float, intrinsics: Intrinsics, fill: float) -> float:
    """The altitude from which a roof ``extent_m`` across (its longest dimension, any
    direction) spans ``fill`` of the photo's shorter side, straight down."""
    half_fov = math.radians(min(intrinsics.hfov_deg, intrinsics.vfov_deg)) / 2.0
    return roof_m + extent_m / 2.0 / (fill * math.tan(half_fov))


def roof_from_photos(
    *,
    centroid1_px: tuple[float, float],
    area1_px: float,
    pose1: CameraPose,
    centroid2_px: tuple[float, float],
    area2_px: float,
    pose2: CameraPose,
    intrinsics: Intrinsics,
) -> float | None:
    """The roof height of one building seen whole in two nadir photos (its outline's
    centroid and area in each, and each camera's pose): the size and triangulation
    estimates, each weighted by the inverse of its expected variance. None when neither
    can tell."""
    a1, a2 = pose1.pos_enu_m[2], pose2.pos_enu_m[2]
    by_size = roof_height_m(area1_px=area1_px, alt1_m=a1, area2_px=area2_px, alt2_m=a2)
    by_rays: float | None = None
    v1 = _run_per_descent(centroid1_px, pose1, intrinsics)
    v2 = _run_per_descent(centroid2_px, pose2, intrinsics)
    bb = 0.0
    if v1 is not None and v2 is not None:
        (x1, y1, _), (x2, y2, _) = pose1.pos_enu_m, pose2.pos_enu_m
        ax = x1 + a1 * v1[0] - x2 - a2 * v2[0]
        ay = y1 + a1 * v1[1] - y2 - a2 * v2[1]
        bx, by = v1[0] - v2[0], v1[1] - v2[1]
        bb = bx * bx + by * by
        if bb > 1e-12:
            by_rays = (ax * bx + ay * by) / bb
    told = [h for h in (by_size, by_rays) if h is not None]
    if not told:
        return None
    # Each estimate's error grows with the roof's distance below the cameras, so both are
    # weighed at one distance: the farther the two put it (at most the ground's). Weighed
    # at its own, an estimate that puts the roof just below the cameras (two sizes that
    # differ by their outlines' error alone, from two altitudes 2 cm apart) would claim an
    # error of millimetres and outweigh the rays (world 50008: 117 m for a 20 m roof).
    low = max(min(told), 0.0)
    estimates: list[tuple[float, float]] = []  # (height, variance)
    if by_size is not None:
        sigma = SIZE_ERROR * (a1 - low) * (a2 - low) / abs(a2 - a1)
        estimates.append((by_size, sigma * sigma))
    if by_rays is not None:
        sigma = CENTROID_ERROR_PX * (min(a1, a2) - low) / intrinsics.fx_px / math.sqrt(bb)
        estimates.append((by_rays, max(sigma * sigma, 1e-12)))
    weight = sum(1.0 / var for _, var in estimates)
    h = sum(est / var for est, var in estimates) / weight
    return h if h < min(a1, a2) else None


def _run_per_descent(
    centroid_px: tuple[float, float], pose: CameraPose, intrinsics: Intrinsics
) -> tuple[float, float] | None:
    """East and north metres the ray through a pixel runs per metre it descends."""
    right, down, forward = pose.axes()
    x = (centroid_px[0] - intrinsics.cx_px) / intrinsics.fx_px
    y = (centroid_px[1] - intrinsics.cy_px) / intrinsics.fy_px
    d = [right[i] * x + down[i] * y + forward[i] for i in range(3)]
    if not d[2] < 0.0:
        return None
    return d[0] / -d[2], d[1] / -d[2]


CUT_FIT_TOLERANCE_PX = 1.5
"""How far (RMS, pixels) the visible edges of a roof cut by one photo's border may lie from
where the other photo's whole outline puts them at the fitted height: about the outline's own
error (half a pixel of tracing, one of simplification) with room for perspective on walls."""


def roof_from_cut_outline(
    *,
    whole_ring_px: Sequence[tuple[float, float]],
    whole_pose: CameraPose,
    cut_ring_px: Sequence[tuple[float, float]],
    cut_pose: CameraPose,
    intrinsics: Intrinsics,
    max_m: float,
    border_px: float = 3.0,
    whole_holes_px: Sequence[Sequence[tuple[float, float]]] = (),
    cut_holes_px: Sequence[Sequence[tuple[float, float]]] = (),
    whole_on_cut: bool = False,
) -> float | None:
    """The height of a roof seen whole in one photo and cut by the other's border: the height
    at which the whole outline, placed on that plane and seen from the other camera, lies on
    the edges the cut outline shows inside the frame (its own border edges say nothing).
    A courtyard's edges (``*_holes_px``) are edges of the roof too.

    With ``whole_on_cut`` the fit is the other way round: every edge of the whole outline
    that falls inside the cut photo's frame must lie on the cut outline. The cut outline may
    hold edges the whole one lacks (a courtyard the border cuts open, walls one camera sees
    and the other does not) that no height puts on the whole outline; the whole outline's
    own edges still meet the cut one's at the roof's height.

    Scans 0..``max_m`` (below both cameras) in metre steps, then refines to a centimetre. None
    when fewer than three metres of edge show inside the frame, when no height puts the edges
    within `CUT_FIT_TOLERANCE_PX`, or when the best height is not clearly the only one (a
    roof straight below both cameras: no parallax).
    """
    k = intrinsics
    samples = [
        p for ring in (cut_ring_px, *cut_holes_px) for p in _inner_edge_points(ring, k, border_px)
    ]
    if len(samples) < 3:
        return None
    top_m = min(max_m, whole_pose.pos_enu_m[2] - 1.0, cut_pose.pos_enu_m[2] - 1.0)
    if top_m <= 0.0:
        return None

    cut_edges = _edge_arrays([np.asarray(r, np.float64) for r in (cut_ring_px, *cut_holes_px)])
    at_points = np.asarray(samples, np.float64)
    carry = _Carrier((whole_ring_px, *whole_holes_px), whole_pose, cut_pose, k)

    def cut_on_whole(h_m: float) -> float:  # pixels
        rings = carry.at(h_m)
        if rings is None:
            return math.inf
        return _rms_to_edge_arrays(at_points, _edge_arrays(rings))

    def whole_on_cut_px(h_m: float) -> float:
        rings = carry.at(h_m)
        if rings is None:
            return math.inf
        listed = [ring.tolist() for ring in rings]
        inside = [p for ring in listed for p in _inner_edge_points(ring, k, border_px)]
        everywhere = sum(_ring_length(ring) for ring in listed) / 2.0  # points every 2 px
        if len(inside) < max(3.0, _INSIDE_SHARE * everywhere):
            return math.inf
        return _rms_to_edge_arrays(np.asarray(inside, np.float64), cut_edges)

    return _fit_height(
        whole_on_cut_px if whole_on_cut else cut_on_whole, top_m, cut_pose.pos_enu_m[2]
    )


def _fit_height(cost: Callable[[float], float], top_m: float, camera_m: float) -> float | None:
    """The height in 0..``top_m`` where ``cost`` (pixels) is least: scanned in metre steps,
    refined to a centimetre; None unless it is within `CUT_FIT_TOLERANCE_PX` and clearly the
    only one (heights 10 % of the way up to the camera, ``camera_m``, fit clearly worse)."""
    steps = int(top_m)
    coarse = [(cost(float(i)), float(i)) for i in range(steps + 1)]
    _, h0 = min(coarse)
    lo, hi = max(h0 - 1.0, 0.0), min(h0 + 1.0, top_m)
    for _ in range(40):  # golden-section search on the bracket around the best metre
        a = hi - (hi - lo) * 0.6180339887498949
        b = lo + (hi - lo) * 0.6180339887498949
        if cost(a) <= cost(b):
            hi = b
        else:
            lo = a
        if hi - lo < 0.01:
            break
    h = (lo + hi) / 2.0
    best = cost(h)
    if not best <= CUT_FIT_TOLERANCE_PX:
        return None
    away_m = 0.1 * (camera_m - h)
    rivals = [cost(x) for x in (h - away_m, h + away_m) if 0.0 <= x <= top_m]
    if rivals and min(rivals) < best + CUT_FIT_TOLERANCE_PX:
        return None
    return h


_INSIDE_SHARE = 1.0 / 3.0
"""The share of the whole outline (carried to the cut photo) that must lie inside its frame
for its edges to be compared with the cut outline's."""


def _ring_length(ring: Sequence[tuple[float, float]]) -> float:
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in _ring_edges(ring))


def outline_residual_px(
    *,
    ring_px: Sequence[tuple[float, float]],
    pose: CameraPose,
    other_ring_px: Sequence[tuple[float, float]],
    other_pose: CameraPose,
    intrinsics: Intrinsics,
    plane_z_m: float,
    border_px: float = 3.0,
) -> float:
    """How well one roof outline, placed on the plane z = ``plane_z_m`` and seen from the
    other camera, lies on the other photo's outline of it: the RMS distance (pixels of the
    other photo) both ways, over the edges inside that frame. About a pixel for one flat roof
    at that height; several where the outlines mix roofs of different heights (tiers of one
    colour) or walls, which no single height explains. inf when nothing can be compared."""
    k = intrinsics
    ring = _reprojected(ring_px, pose, other_pose, k, plane_z_m)
    if ring is None:
        return math.inf
    there = _inner_edge_points(other_ring_px, k, border_px)
    here = _inner_edge_points(ring, k, border_px)
    if len(there) < 3 or len(here) < 3:
        return math.inf
    return max(
        _rms_to_edges(there, _ring_edges(ring)), _rms_to_edges(here, _ring_edges(other_ring_px))
    )


def _rms_to_edges(
    points: Sequence[tuple[float, float]],
    edges: Sequence[tuple[tuple[float, float], tuple[float, float]]],
) -> float:
    """RMS of each point's distance to the nearest of ``edges``."""
    ends = np.asarray(edges, dtype=np.float64)
    return _rms_to_edge_arrays(np.asarray(points, np.float64), (ends[:, 0], ends[:, 1]))


_Edges = tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]
"""Edges as two (n, 2) arrays: where each starts, where it ends."""


def _edge_arrays(rings: Sequence[npt.NDArray[np.float64]]) -> _Edges:
    """Every edge of closed ``rings`` ((n, 2) arrays of vertices)."""
    return (
        np.concatenate(rings),
        np.concatenate([np.roll(ring, -1, axis=0) for ring in rings]),
    )


def _rms_to_edge_arrays(points: npt.NDArray[np.float64], edges: _Edges) -> float:
    """RMS of each point's ((n, 2) array) distance to the nearest of ``edges``: the arithmetic
    of `~uavtool.nav.geometry.point_segment_distance`, step for step, on every pair at once
    (the same floats), the squares summed in order."""
    a, b = edges
    px, py = points[:, 0:1], points[:, 1:2]
    ax, ay = a[:, 0], a[:, 1]
    dx, dy = b[:, 0] - ax, b[:, 1] - ay
    den = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((px - ax) * dx + (py - ay) * dy) / den
    t = np.where(den == 0.0, 0.0, np.minimum(1.0, np.maximum(0.0, t)))
    ex, ey = px - (ax + t * dx), py - (ay + t * dy)
    nearest = np.sqrt(ex * ex + ey * ey).min(axis=1)
    total = float(np.add.accumulate(nearest * nearest)[-1])  # in order, as a loop would
    return math.sqrt(total / len(points))


def _inner_edge_points(
    ring_px: Sequence[tuple[float, float]], k: Intrinsics, border_px: float
) -> list[tuple[float, float]]:
    """Points every two pixels along the ring's edges, those at least ``border_px`` inside
    the frame (the frame's border is where the outline was cut, not an edge of the roof)."""
    out = []
    lo_u, hi_u = border_px, k.width_px - 1.0 - border_px
    lo_v, hi_v = border_px, k.height_px - 1.0 - border_px
    for a, b in _ring_edges(ring_px):
        n = max(1, int(math.hypot(b[0] - a[0], b[1] - a[1]) / 2.0))
        for i in range(n):
            t = i / n
            u, v = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            if lo_u <= u <= hi_u and lo_v <= v <= hi_v:
                out.append((u, v))
    return out


def _ring_edges(
    ring: Sequence[tuple[float, float]],
) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    n = len(ring)
    return [(ring[i], ring[(i + 1) % n]) for i in range(n)]


def _reprojected(
    ring_px: Sequence[tuple[float, float]],
    pose: CameraPose,
    other: CameraPose,
    k: Intrinsics,
    plane_z_m: float,
) -> list[tuple[float, float]] | None:
    """``ring_px`` of ``pose``'s photo placed on the plane z = ``plane_z_m`` and seen from
    ``other``: its pixels there (None if a vertex falls behind that camera)."""
    rings = _Carrier([ring_px], pose, other, k).at(plane_z_m)
    return None if rings is None else [(u, v) for u, v in rings[0].tolist()]


class _Carrier:
    """Rings of one photo placed on planes z = h and seen from another camera: each vertex's
    ray, which the plane does not change, worked out once, then every vertex of a ring
    carried at once."""

    def __init__(
        self,
        rings: Sequence[Sequence[tuple[float, float]]],
        pose: CameraPose,
        other: CameraPose,
        k: Intrinsics,
    ) -> None:
        right, down, forward = pose.axes()
        self._right, self._down, self._forward = other.axes()
        self._camera, self._other, self._k = pose.pos_enu_m, other.pos_enu_m, k
        self._rays: list[npt.NDArray[np.float64]] | None = []
        for ring in rings:
            rays = []
            for u, v in ring:
                x = (u - k.cx_px) / k.fx_px
                y = (v - k.cy_px) / k.fy_px
                d = [right[i] * x + down[i] * y + forward[i] for i in range(3)]
                if not d[2] < 0.0:
                    self._rays = None  # a vertex above the horizon: on no plane below
                    return
                rays.append(d)
            self._rays.append(np.asarray(rays, np.float64).reshape(-1, 3))

    def at(self, plane_z_m: float) -> list[npt.NDArray[np.float64]] | None:
        """Each ring's pixels ((n, 2) arrays) in the other photo, on the plane z =
        ``plane_z_m``; None if a vertex falls behind the other camera."""
        if self._rays is None:
            return None
        (cx, cy, cz), (ox, oy, oz), k = self._camera, self._other, self._k
        o_right, o_down, o_forward = self._right, self._down, self._forward
        out = []
        for d in self._rays:
            t = (cz - plane_z_m) / -d[:, 2]
            p0 = cx + t * d[:, 0] - ox
            p1 = cy + t * d[:, 1] - oy
            p2 = plane_z_m - oz
            depth = p0 * o_forward[0] + p1 * o_forward[1] + p2 * o_forward[2]
            if not bool(np.all(depth > 0.0)):
                return None
            u = k.fx_px * (p0 * o_right[0] + p1 * o_right[1] + p2 * o_right[2]) / depth + k.cx_px
            v = k.fy_px * (p0 * o_down[0] + p1 * o_down[1] + p2 * o_down[2]) / depth + k.cy_px
            out.append(np.stack([u, v], axis=1))
        return out


def nadir_px(pose: CameraPose, intrinsics: Intrinsics) -> tuple[float, float]:
    """The pixel straight below the camera: where a wall's foot and top line up, the foot
    nearer."""
    x, y, z = pose.pos_enu_m
    u0, v0, _ = project(np.array([[x, y, z - 1.0]]), pose, intrinsics)[0]
    return float(u0), float(v0)


def higher_part_m(
    walls_px: Sequence[npt.NDArray[np.int32]],
    pose: CameraPose,
    intrinsics: Intrinsics,
    *,
    roof_m: float,
) -> float | None:
    """How high, at least, the part of a building stands whose walls a nadir photo shows
    inside the roof at ``roof_m`` (``walls_px``: each wall's pixels). A wall's foot and top
    lie on one ray from the photo's nadir point, the top further out: at radii ``ρ_foot``
    and ``ρ_top`` with ``ρ_foot / ρ_top = (A - top) / (A - foot)`` for a camera ``A`` up.
    With its foot on the roof (a higher part may stand on a part higher still, so this is a
    least height), ``top = roof + (A - roof) (1 - ρ_foot / ρ_top)``; the strip's radial
    width is taken a pixel narrower than seen, for its pixels' edges. None without walls, or
    for a photo not taken straight down."""
    if not walls_px or abs(pose.pitch_deg + 90.0) > _NADIR_DEG:
        return None
    u0, v0 = nadir_px(pose, intrinsics)
    above_m = pose.pos_enu_m[2] - roof_m
    if not above_m > 0.0:
        return None
    tops: list[float] = []
    for wall in walls_px:
        du = wall[:, 0].astype(np.float64) - u0
        dv = wall[:, 1].astype(np.float64) - v0
        rho = np.hypot(du, dv)
        if float(rho.max()) < 2.0:
            continue  # straight under the camera: no perspective to go by
        step = 1.0 / max(float(rho.mean()), 1.0)  # about a pixel of arc
        bins = np.floor(np.arctan2(dv, du) / step).astype(np.int64)
        # a set and a sorted median, as np.unique and np.median give them, without their
        # import of numpy.ma (~20 ms of a flight)
        heights = []
        for b in sorted(set(bins.tolist())):
            r = rho[bins == b]
            width = float(r.max() - r.min())  # a pixel narrower than its pixels span
            heights.append(roof_m + above_m * width / (float(r.max()) + 0.5))
        heights.sort()
        k = len(heights) // 2
        tops.append(heights[k] if len(heights) % 2 else (heights[k - 1] + heights[k]) / 2.0)
    return max(tops, default=None)


_NADIR_DEG = 10.0
"""How far from straight down a photo may look for :func:`higher_part_m`."""
