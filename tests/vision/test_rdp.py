from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from uavtool.vision.rdp import rdp, rdp_indices, rdp_ring, rdp_ring_indices, rdp_rings_indices

# Pixel coordinates to a millionth of a pixel: two points are equal or at least 1e-6 apart
# (points a subnormal distance apart are not pixels, and their squared distance underflows).
coords = st.floats(min_value=-500, max_value=500).map(lambda v: round(v, 6))


def _dist_to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    den = float(ab @ ab)
    t = 0.0 if den == 0 else min(1.0, max(0.0, float((p - a) @ ab) / den))
    return float(np.linalg.norm(p - (a + t * ab)))


@settings(max_examples=150, deadline=None)
@given(
    pts=arrays(np.float64, st.tuples(st.integers(2, 60), st.just(2)), elements=coords),
    eps=st.floats(0.0, 50.0),
)
def test_rdp_keeps_a_subset_within_epsilon(pts: np.ndarray, eps: float) -> None:
    idx = rdp_indices(pts, eps)
    assert idx[0] == 0
    assert idx[-1] == len(pts) - 1
    assert np.all(np.diff(idx) > 0)  # in order, no repeats
    out = rdp(pts, eps)
    assert np.array_equal(out, pts[idx])  # a subset of the input points
    for k in range(len(idx) - 1):
        a, b = pts[idx[k]], pts[idx[k + 1]]
        for p in pts[idx[k] : idx[k + 1] + 1]:
            assert _dist_to_segment(p, a, b) <= eps + 1e-9


@settings(max_examples=100, deadline=None)
@given(
    pts=arrays(np.float64, st.tuples(st.integers(4, 60), st.just(2)), elements=coords),
    eps=st.floats(0.0, 50.0),
)
def test_rdp_ring_keeps_a_subset_within_epsilon(pts: np.ndarray, eps: float) -> None:
    kept = rdp_ring_indices(pts, eps).tolist()
    assert np.array_equal(rdp_ring(pts, eps), pts[kept])  # a subset of the input points
    assert len(set(kept)) == len(kept)
    # Kept points keep their cyclic order: rotate so the smallest index comes first.
    start = kept.index(min(kept))
    cyc = kept[start:] + kept[:start]
    assert cyc == sorted(cyc)
    m = len(kept)
    for k in range(m):
        i, j = kept[k], kept[(k + 1) % m]
        span = range(i, j + 1) if j > i else [*range(i, len(pts)), *range(j + 1)]
        for q in span:
            assert _dist_to_segment(pts[q], pts[i], pts[j]) <= eps + 1e-9


@settings(max_examples=60, deadline=None)
@given(
    rings=st.lists(
        arrays(np.float64, st.tuples(st.integers(1, 40), st.just(2)), elements=coords),
        max_size=6,
    ),
    eps=st.floats(0.0, 20.0),
)
def test_rings_simplified_together_are_simplified_as_alone(
    rings: list[np.ndarray], eps: float
) -> None:
    together = rdp_rings_indices(rings, eps)
    assert len(together) == len(rings)
    for ring, kept in zip(rings, together, strict=True):
        assert np.array_equal(kept, rdp_ring_indices(ring, eps))


def test_rdp_ring_reduces_a_dense_square_to_its_corners() -> None:
    side = np.linspace(0, 100, 51)[:-1]
    ring = np.concatenate(
        [
            np.stack([side, np.zeros(50)], 1),
            np.stack([np.full(50, 100.0), side], 1),
            np.stack([100 - side, np.full(50, 100.0)], 1),
            np.stack([np.zeros(50), 100 - side], 1),
        ]
    )
    out = rdp_ring(ring, 0.5)
    assert sorted(map(tuple, out.tolist())) == [(0, 0), (0, 100), (100, 0), (100, 100)]
