"""The alignment behind :func:`uavtool.vision.recognize.match`: an edit distance between two
cyclic symbol sequences whose edits are merges of consecutive corners.

The reference sequence is doubled so a window of ``n`` reference symbols may start at any
corner; the dynamic programme runs for every reference start at once and, in the same
array calls, for each of the few candidate corners the candidate may be read from. Only
IEEE + − × ÷, exact minima and ``math`` on scalars, so scores are bit-identical everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.geo import wrap_180
from uavtool.vision.params import RecognizeParams
from uavtool.vision.shapes import FloatArray

Pairs = tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]


@dataclass(frozen=True, slots=True)
class Symbols:
    """The symbol sequence of one outline.

    ``turn_deg`` : (n,) — signed turning angle at each corner (positive turns the way the
    outline runs); ``length_rel`` : (n,) — the edge leaving each corner over the perimeter;
    ``ring_px`` : (n, 2) — the corners, normalised orientation.
    """

    turn_deg: FloatArray
    length_rel: FloatArray
    ring_px: FloatArray
    perimeter_px: float


@dataclass(frozen=True, slots=True)
class Match:
    """The best alignment of a candidate outline with a reference outline.

    ``pairs`` lists matched corner groups: reference corner indices with the candidate
    corner indices they stand for. ``rotation_deg`` turns the reference into the candidate
    (clockwise on screen, y down); ``scale`` is candidate perimeter over reference perimeter.
    ``judgeable`` is False when either outline is cut by its image border: part of the
    shape is missing, so the score says nothing either way (it is still computed).
    """

    score: float
    cost: float
    pairs: Pairs
    rotation_deg: float
    scale: float
    mirrored: bool
    judgeable: bool = True


NO_MATCH = Match(0.0, math.inf, (), 0.0, 0.0, False)


def align(ref: Symbols, cand: Symbols, p: RecognizeParams, *, mirrored: bool) -> Match:
    """The best alignment, reading the candidate from each of its corners in turn.

    The reference is doubled, so its groups may start anywhere; the candidate is read once
    round, so a group of its corners cannot wrap past its first corner. Reading it from
    every corner (all in the same array calls) lets a group start anywhere too. Starts are
    tried from the sharpest corner on; the first wins ties.
    """
    n_a, n_b = len(ref.turn_deg), len(cand.turn_deg)
    if n_b < 3:
        return NO_MATCH
    turns = [abs(t) for t in cand.turn_deg.tolist()]
    sharpest = max(range(n_b), key=lambda i: (turns[i], -i))
    # Every corner may be where a group starts (a step in an edge makes its sharpest
    # corners ones to drop), so the candidate is read from each, sharpest first.
    starts = [(sharpest + i) % n_b for i in range(n_b)]
    if n_a < 3:
        return Match(0.0, math.inf, (), 0.0, 0.0, False)
    mean_n = 0.5 * (n_a + n_b)
    final, move_of, moves = _programme(ref, cand, starts, mean_n, p)
    best: tuple[int, int, float] | None = None  # (start number, reference start, score)
    for c in range(len(starts)):
        s = int(np.argmin(final[c]))
        cost = float(final[c, s])
        score = max(0.0, 1.0 - cost / mean_n) if math.isfinite(cost) else 0.0
        if best is None or score > best[2]:
            best = (c, s, score)
    assert best is not None
    c, s, score = best
    cost = float(final[c, s])
    if not math.isfinite(cost):
        return Match(0.0, math.inf, (), 0.0, 0.0, False)
    start = starts[c]
    pairs = tuple(
        (r, tuple((j + start) % n_b for j in cs))
        for r, cs in _backtrack(move_of[:, :, c], moves, s, n_a, n_b)
    )
    rotation = _rotation_deg(ref.ring_px, cand.ring_px, pairs)
    if mirrored:
        rotation = -rotation
    return Match(score, cost, pairs, rotation, cand.perimeter_px / ref.perimeter_px, mirrored)


def _programme(
    ref: Symbols, cand: Symbols, starts: list[int], mean_n: float, p: RecognizeParams
) -> tuple[FloatArray, npt.NDArray[np.intp], list[tuple[int, int]]]:
    """The dynamic programme for every candidate start (axis 2) and reference start (axis 3).

    Returns the final costs ``(starts, n_a)``, the move chosen at every cell ``(n_a + 1,
    n_b + 1, starts, n_a)`` and the list of moves ``(a, b)``: ``a`` reference corners
    against ``b`` candidate corners, one side always a single corner.
    """
    n_a, n_b = len(ref.turn_deg), len(cand.turn_deg)
    k_max = min(p.max_merge, n_a, n_b)
    tables_a = [_group_tables(ref, k, mean_n, p) for k in range(1, k_max + 1)]
    tables_b = [_group_tables(cand, k, mean_n, p) for k in range(1, k_max + 1)]
    moves = [(1, 1)] + [(a, 1) for a in range(2, k_max + 1)] + [(1, b) for b in range(2, k_max + 1)]
    # Candidate row r read from start c is row (r + c) mod n_b of the unrotated tables.
    rows = (np.arange(n_b)[:, None] + np.array(starts)[None, :]) % n_b
    # cost[(a, b)] : (n_b, starts, 2·n_a) — reference group (a corners from the column,
    # mod n_a) against candidate group (b corners from the row), doubled along the
    # reference so a window of n_a columns starting anywhere is a plain slice.
    cost: dict[tuple[int, int], FloatArray] = {}
    for a, b in moves:
        ta, la, pa = tables_a[a - 1]
        tb, lb, pb = tables_b[b - 1]
        c = (
            np.abs(tb[:, None] - ta[None, :]) / p.angle_scale_deg
            + np.abs(lb[:, None] - la[None, :]) * mean_n / p.length_scale
            + pb[:, None]
            + pa[None, :]
        )
        cost[(a, b)] = np.concatenate([c, c], axis=1)[rows]
    shape = (n_b + 1, len(starts), n_a)
    # dist[i] — best cost having used i reference and j (axis 0) candidate corners.
    dist = np.full((n_a + 1, *shape), math.inf)
    dist[0, 0] = 0.0
    move_of = np.zeros((n_a + 1, *shape), dtype=np.intp)
    # One slot per move; a move taking b candidate corners never reaches rows j < b, and
    # a slot stays at infinity until i reaches its a.
    step = np.full((len(moves), *shape), math.inf)
    for i in range(1, n_a + 1):
        for m, (a, b) in enumerate(moves):
            if a <= i:
                r = (i - a) % n_a
                np.add(
                    dist[i - a, : n_b + 1 - b],
                    cost[(a, b)][: n_b + 1 - b, :, r : r + n_a],
                    out=step[m, b:],
                )
        # argmin keeps the first move among equals, as a running "strictly better" would.
        np.argmin(step, axis=0, out=move_of[i])
        np.min(step, axis=0, out=dist[i])
    return dist[n_a, n_b], move_of, moves


def _group_tables(
    sym: Symbols, k: int, mean_n: float, p: RecognizeParams
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """For groups of ``k`` consecutive corners starting at each corner: summed turn, summed
    length, and the merge penalty of dropping the ``k − 1`` inner corners."""
    n = len(sym.turn_deg)
    turn2 = np.concatenate([sym.turn_deg, sym.turn_deg])
    length2 = np.concatenate([sym.length_rel, sym.length_rel])
    turn = sym.turn_deg
    length = sym.length_rel
    if k == 1:
        return turn, length, np.zeros(n)
    for j in range(1, k):
        turn = turn + turn2[j : j + n]
        length = length + length2[j : j + n]
    # The k − 1 inner corners are dropped: the outline then runs straight from the group's
    # first corner to the corner after it. That changes the shape by the area between the
    # dropped path and that chord (summed as a fan of triangles from the first corner, so a
    # step's two sides do not cancel), and losing a share of the shape's area costs that
    # share of the score: nothing for a vertex on a straight edge, little for a corner that
    # simplification split or a step in an edge, a wing's share for a real corner.
    ring = sym.ring_px
    ring2 = np.concatenate([ring, ring])
    x, y = ring[:, 0], ring[:, 1]
    area = 0.5 * abs(math.fsum((x * np.roll(y, -1) - np.roll(x, -1) * y).tolist()))
    changed = np.zeros(n)
    for j in range(1, k):
        a = ring2[j : j + n] - ring
        b = ring2[j + 1 : j + 1 + n] - ring
        changed = changed + 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    dropped = changed / area * mean_n if area > 0.0 else np.full(n, math.inf)
    return turn, length, (k - 1) * p.merge_cost + dropped


def _backtrack(
    move_of: npt.NDArray[np.intp], moves: list[tuple[int, int]], s: int, n_a: int, n_b: int
) -> Pairs:
    pairs: list[tuple[tuple[int, ...], tuple[int, ...]]] = []
    i, j = n_a, n_b
    while i > 0:
        a, b = moves[int(move_of[i, j, s])]
        ref_idx = tuple((s + i - a + t) % n_a for t in range(a))
        cand_idx = tuple(j - b + t for t in range(b))
        pairs.append((ref_idx, cand_idx))
        i, j = i - a, j - b
    return tuple(reversed(pairs))


def _rotation_deg(ref: FloatArray, cand: FloatArray, pairs: Pairs) -> float:
    """Length-weighted circular mean of the angle between matched edge chords."""
    n_a, n_b = len(ref), len(cand)
    sx: list[float] = []
    sy: list[float] = []
    for ref_idx, cand_idx in pairs:
        ra = ref[(ref_idx[-1] + 1) % n_a] - ref[ref_idx[0]]
        cb = cand[(cand_idx[-1] + 1) % n_b] - cand[cand_idx[0]]
        angle = math.atan2(float(cb[1]), float(cb[0])) - math.atan2(float(ra[1]), float(ra[0]))
        weight = math.hypot(float(ra[0]), float(ra[1])) * math.hypot(float(cb[0]), float(cb[1]))
        sx.append(weight * math.cos(angle))
        sy.append(weight * math.sin(angle))
    return wrap_180(math.degrees(math.atan2(math.fsum(sy), math.fsum(sx))))
