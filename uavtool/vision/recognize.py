"""Syntactic shape recognition (paper III-B): rotation- and scale-invariant outline matching.

An outline becomes a cyclic sequence of symbols, one per corner: the turning angle at the
corner and the length of the edge leaving it, relative to the perimeter. The reference
sequence is doubled, so aligning the candidate against every window of ``n`` consecutive
reference symbols tries every starting corner. The alignment is an edit distance whose
edits are merges: ``k`` consecutive corners of one outline may stand for one corner of the
other (their turns and edges add up), cheap when the dropped corners stand close to the
straight edge that replaces them (a vertex left on a straight edge, a corner that
simplification split, the step between two roofs of one building seen in perspective).

The alignment itself is in :mod:`uavtool.vision.align`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from uavtool.geo import wrap_180
from uavtool.vision.align import NO_MATCH, Match, Symbols, align
from uavtool.vision.params import RecognizeParams
from uavtool.vision.shapes import FloatArray, Shape, orient, perimeter

__all__ = [
    "NO_MATCH",
    "Match",
    "Symbols",
    "best_match",
    "match",
    "match_shapes",
    "mirror_score",
    "symbols",
]


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
    """Match two shapes' outer outlines; differing hole counts lower the score. The match
    is not ``judgeable`` when either shape is cut by its image border."""
    p = params if params is not None else RecognizeParams()
    return _match_shapes(reference, symbols(reference.polygon_px), candidate, p)


def match(
    reference_px: FloatArray, candidate_px: FloatArray, params: RecognizeParams | None = None
) -> Match:
    """Align a candidate ring ``(m, 2)`` with a reference ring ``(n, 2)``; score in [0, 1]."""
    p = params if params is not None else RecognizeParams()
    return _match(symbols(reference_px), candidate_px, p)


def best_match(
    reference: Shape, candidates: tuple[Shape, ...], params: RecognizeParams | None = None
) -> tuple[int, tuple[Match, ...]]:
    """Every candidate's match against the reference, and the index of the best judgeable one
    (−1 if none): a shape cut by the image border is never the best, whatever its score."""
    p = params if params is not None else RecognizeParams()
    ref = symbols(reference.polygon_px)
    matches = tuple(_match_shapes(reference, ref, c, p) for c in candidates)
    judged = [i for i, m in enumerate(matches) if m.judgeable]
    if not judged:
        return -1, matches
    return max(judged, key=lambda i: (matches[i].score, -i)), matches


def mirror_score(
    reference: Shape, candidate: Shape, params: RecognizeParams | None = None
) -> float:
    """How well ``candidate`` matches the mirror image of ``reference`` (differing hole counts
    lower it as in :func:`match_shapes`). ``mirror_score(s, s)`` says how chiral a shape is:
    1 for a shape that is its own mirror image (a rectangle, a T), lower for an L."""
    p = params if params is not None else RecognizeParams()
    flipped = np.asarray(candidate.polygon_px, dtype=np.float64) * np.array([-1.0, 1.0])
    score = align(symbols(reference.polygon_px), symbols(flipped), p, mirrored=True).score
    holes = abs(len(reference.holes_px) - len(candidate.holes_px))
    return max(0.0, score - p.hole_penalty * holes) if holes and score else score


def _match_shapes(reference: Shape, ref: Symbols, candidate: Shape, p: RecognizeParams) -> Match:
    result = _match(ref, candidate.polygon_px, p)
    holes = abs(len(reference.holes_px) - len(candidate.holes_px))
    score = result.score
    if holes != 0 and score != 0.0:
        score = max(0.0, score - p.hole_penalty * holes)
    judgeable = not (reference.cut_by_border or candidate.cut_by_border)
    if score == result.score and judgeable:
        return result
    return replace(result, score=score, judgeable=judgeable)


def _match(ref: Symbols, candidate_px: FloatArray, p: RecognizeParams) -> Match:
    best = align(ref, symbols(candidate_px), p, mirrored=False)
    if p.allow_mirror:
        flipped = np.asarray(candidate_px, dtype=np.float64) * np.array([-1.0, 1.0])
        other = align(ref, symbols(flipped), p, mirrored=True)
        if other.score > best.score:
            best = other
    return best


def _dedupe(ring: FloatArray) -> FloatArray:
    d = np.concatenate([ring[1:], ring[:1]]) - ring
    keep = (d[:, 0] != 0.0) | (d[:, 1] != 0.0)
    out: FloatArray = ring[keep]
    return out
