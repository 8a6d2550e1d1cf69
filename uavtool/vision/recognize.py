"""Syntactic shape recognition (paper III-B): rotation- and scale-invariant outline matching.

An outline becomes a cyclic sequence of symbols, one per corner: the turning angle at the
corner and the length of the edge leaving it, relative to the perimeter. The reference
sequence is doubled, so aligning the candidate against every window of ``n`` consecutive
reference symbols tries every starting corner. The alignment is an edit distance whose
edits are merges: ``k`` consecutive corners of one outline may stand for one corner of the
other (their turns and edges add up), cheap when the dropped corner barely turns (a vertex
left on a straight edge) or the dropped edge is short (a corner that simplification split).

All starting corners are aligned at once (numpy over the start axis, a Python loop over the
reference's corners); only IEEE + − × ÷ and ``math`` functions on scalars, so scores are
bit-identical everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uavtool.geo import wrap_180
from uavtool.vision.params import RecognizeParams
from uavtool.vision.shapes import FloatArray, Shape, orient, perimeter


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
    """

    score: float
    cost: float
    pairs: tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]
    rotation_deg: float
    scale: float
    mirrored: bool


NO_MATCH = Match(0.0, math.inf, (), 0.0, 0.0, False)


def symbols(ring_px: FloatArray) -> Symbols:
    """The symbol sequence of a closed ring ``(n, 2)`` (orientation normalised)."""
    ring = _dedupe(orient(np.asarray(ring_px, dtype=np.float64), positive=True))
    n = len(ring)
    if n < 3:
        empty = np.zeros(0)
        return Symbols(empty, empty, ring, 0.0)
    d = np.concatenate([ring[1:], ring[:1]]) - ring
    heading = [math.degrees(math.atan2(float(dy), float(dx))) for dx, dy in d.tolist()]
    turn = np.array([wrap_180(heading[i] - heading[i - 1]) for i in range(n)])
    per = perimeter(ring)
    length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]) / per
    return Symbols(turn, length, ring, per)


def match_shapes(
    reference: Shape, candidate: Shape, params: RecognizeParams | None = None
) -> Match:
    """Match two shapes' outer outlines; differing hole counts lower the score."""
    p = params if params is not None else RecognizeParams()
    result = match(reference.polygon_px, candidate.polygon_px, p)
    holes = abs(len(reference.holes_px) - len(candidate.holes_px))
    if holes == 0 or result.score == 0.0:
        return result
    score = max(0.0, result.score - p.hole_penalty * holes)
    return Match(
        score, result.cost, result.pairs, result.rotation_deg, result.scale, result.mirrored
    )


def match(
    reference_px: FloatArray, candidate_px: FloatArray, params: RecognizeParams | None = None
) -> Match:
    """Align a candidate ring ``(m, 2)`` with a reference ring ``(n, 2)``; score in [0, 1]."""
    p = params if params is not None else RecognizeParams()
    ref = symbols(reference_px)
    cand = symbols(candidate_px)
    best = _align_any_start(ref, cand, p, mirrored=False)
    if p.allow_mirror:
        flipped = np.asarray(candidate_px, dtype=np.float64) * np.array([-1.0, 1.0])
        other = _align_any_start(ref, symbols(flipped), p, mirrored=True)
        if other.score > best.score:
            best = other
    return best


def best_match(
    reference: Shape, candidates: tuple[Shape, ...], params: RecognizeParams | None = None
) -> tuple[int, tuple[Match, ...]]:
    """Every candidate's match against the reference and the index of the best (−1 if none)."""
    matches = tuple(match_shapes(reference, c, params) for c in candidates)
    if not matches:
        return -1, matches
    scores = [m.score for m in matches]
    best = max(range(len(scores)), key=lambda i: (scores[i], -i))
    return best, matches


def _align_any_start(ref: Symbols, cand: Symbols, p: RecognizeParams, *, mirrored: bool) -> Match:
    """Align with the candidate read from a corner that surely starts a merge group.

    The reference is doubled, so its groups may start anywhere; the candidate is read once
    from its first corner, so a group of its corners cannot wrap past the end. Starting at
    its sharpest corner — and also just before it when the corners before it are weak
    (small turn or short edge, i.e. candidates for merging) — avoids that.
    """
    n = len(cand.turn_deg)
    if n < 3:
        return NO_MATCH
    turns = [abs(t) for t in cand.turn_deg.tolist()]
    lengths = cand.length_rel.tolist()
    sharpest = max(range(n), key=lambda i: (turns[i], -i))
    starts = [sharpest]
    for back in range(1, min(p.max_merge, n)):
        prev = (sharpest - back) % n
        weak = turns[prev] < 0.5 * p.angle_scale_deg or lengths[prev] * n < 0.5
        if not weak:
            break
        starts.append(prev)
    best = NO_MATCH
    for start in starts:
        m = _align(ref, _rotated(cand, start), p, mirrored=mirrored)
        if m.score > best.score or best is NO_MATCH:
            pairs = tuple((r, tuple((c + start) % n for c in cs)) for r, cs in m.pairs)
            best = Match(m.score, m.cost, pairs, m.rotation_deg, m.scale, m.mirrored)
    return best


def _rotated(sym: Symbols, start: int) -> Symbols:
    """The same outline read from corner ``start``."""
    order = [(start + i) % len(sym.turn_deg) for i in range(len(sym.turn_deg))]
    return Symbols(sym.turn_deg[order], sym.length_rel[order], sym.ring_px[order], sym.perimeter_px)


def _dedupe(ring: FloatArray) -> FloatArray:
    d = np.concatenate([ring[1:], ring[:1]]) - ring
    keep = (d[:, 0] != 0.0) | (d[:, 1] != 0.0)
    out: FloatArray = ring[keep]
    return out


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
    penalty = np.zeros(n)
    for j in range(1, k):
        nxt_turn = turn2[j : j + n]
        prev_len = length2[j - 1 : j - 1 + n]
        turn = turn + nxt_turn
        length = length + length2[j : j + n]
        dropped = np.minimum(
            np.abs(nxt_turn) / p.angle_scale_deg, prev_len * mean_n / p.length_scale
        )
        penalty = penalty + (p.merge_cost + dropped)
    return turn, length, penalty


def _align(ref: Symbols, cand: Symbols, p: RecognizeParams, *, mirrored: bool) -> Match:
    n_a, n_b = len(ref.turn_deg), len(cand.turn_deg)
    if n_a < 3 or n_b < 3:
        return NO_MATCH
    mean_n = 0.5 * (n_a + n_b)
    k_max = min(p.max_merge, n_a, n_b)
    tables_a = [_group_tables(ref, k, mean_n, p) for k in range(1, k_max + 1)]
    tables_b = [_group_tables(cand, k, mean_n, p) for k in range(1, k_max + 1)]
    moves = [(1, 1)] + [(a, 1) for a in range(2, k_max + 1)] + [(1, b) for b in range(2, k_max + 1)]
    # cost2[(a, b)] : (n_b, 2·n_a) — cost of reference group (a corners from column index,
    # mod n_a) against candidate group (b corners from row index); doubled along the
    # reference axis so a window of n_a columns starting anywhere is a plain slice.
    cost2: dict[tuple[int, int], FloatArray] = {}
    for a, b in moves:
        ta, la, pa = tables_a[a - 1]
        tb, lb, pb = tables_b[b - 1]
        c = (
            np.abs(tb[:, None] - ta[None, :]) / p.angle_scale_deg
            + np.abs(lb[:, None] - la[None, :]) * mean_n / p.length_scale
            + pb[:, None]
            + pa[None, :]
        )
        cost2[(a, b)] = np.concatenate([c, c], axis=1)
    inf = math.inf
    # dist[i] : (n_b + 1, n_a) — best cost having used i reference and j candidate corners,
    # for every start corner s (last axis).
    dist = np.full((n_a + 1, n_b + 1, n_a), inf)
    move_of = np.full((n_a + 1, n_b + 1, n_a), -1, dtype=np.int8)
    dist[0, 0, :] = 0.0
    for i in range(1, n_a + 1):
        row = dist[i]
        row_move = move_of[i]
        for m, (a, b) in enumerate(moves):
            if a > i or b > n_b:
                continue
            r = (i - a) % n_a
            step = dist[i - a, : n_b + 1 - b, :] + cost2[(a, b)][: n_b + 1 - b, r : r + n_a]
            target = row[b:]
            better = step < target
            target[better] = step[better]
            row_move[b:][better] = m
    final = dist[n_a, n_b]
    s = int(np.argmin(final))
    cost = float(final[s])
    if not math.isfinite(cost):
        return NO_MATCH
    pairs = _backtrack(move_of, moves, s, n_a, n_b)
    score = max(0.0, 1.0 - cost / mean_n)
    rotation = _rotation_deg(ref.ring_px, cand.ring_px, pairs)
    if mirrored:
        rotation = -rotation
    return Match(score, cost, pairs, rotation, cand.perimeter_px / ref.perimeter_px, mirrored)


def _backtrack(
    move_of: npt.NDArray[np.int8], moves: list[tuple[int, int]], s: int, n_a: int, n_b: int
) -> tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]:
    pairs: list[tuple[tuple[int, ...], tuple[int, ...]]] = []
    i, j = n_a, n_b
    while i > 0:
        a, b = moves[int(move_of[i, j, s])]
        ref_idx = tuple((s + i - a + t) % n_a for t in range(a))
        cand_idx = tuple(j - b + t for t in range(b))
        pairs.append((ref_idx, cand_idx))
        i, j = i - a, j - b
    return tuple(reversed(pairs))


def _rotation_deg(
    ref: FloatArray, cand: FloatArray, pairs: tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]
) -> float:
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
