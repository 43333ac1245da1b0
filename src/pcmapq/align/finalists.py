"""The choice among a map's candidate poses: each refined roughly, the best few (and any
close one elsewhere) refined to the end, the best of those by support (fitness, lowered by what
the map's free space costs the pose where it has free space), then RMSE; with the scale free, a
near tie broken by the share of the truth each pose covers."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np

from pcmapq.align.free_space import PENALTY, cost
from pcmapq.core.transform import Similarity2D, wrapped

#: A rough-stage result whose support is at least this share of the best one's goes through the
#: fine stages too, beyond the ``finalists``: clutter can drag the rough stage of the right
#: start below a wrong pose's, which the fine stages then overtake
#: (``tests/e2e/test_placement.py``, a plan under 800 boxes).
CLOSE_FINALISTS = 0.9
#: ... when it is another pose than every finalist's: farther than these, metres and degrees.
SAME_POSE_M, SAME_POSE_DEG = 1.0, 5.0
#: With the scale free, finalists whose fitness is within this of the best one's are told apart
#: by the share of the truth's walls they cover: a map's fitness barely changes when it is
#: shrunk into a part of the truth that looks like it, the walls it covers do (a bent map of a
#: small building fits as well at half its scale in one half of it, covering far fewer of the
#: truth's walls; ``tests/realdata/test_scale_halmstad.py``).
TIE_FITNESS = 0.02
#: ... when it covers at least this share of the truth more than the fittest finalist does.
TIE_COVERAGE = 0.05

#: One refinement: a map -> truth transform in, the refined one out.
Refine = Callable[[Similarity2D], Similarity2D]


class Scored(Protocol):
    """A pose and its score (:class:`~pcmapq.align.planar.Alignment`)."""

    transform: Similarity2D
    fitness: float
    rmse_m: float
    contradiction: float | None
    free_on_truth: float | None


def refine_best(starts: Sequence[Similarity2D], rough: Refine, fine: Refine,
                scored: Callable[[Similarity2D], Scored], finalists: int, *,
                covered: Callable[[Similarity2D], float] | None = None,
                finals_out: list[Scored] | None = None) -> Similarity2D:
    """Every start refined by ``rough``; the ``finalists`` best of those (highest support, then
    lowest RMSE, by ``scored``; see :func:`support`), and any other pose within
    CLOSE_FINALISTS of the best support, refined by ``fine``; the best of these. Given
    ``covered`` (the share of the truth a pose covers), the one covering most among those
    within TIE_FITNESS of the best fitness wins instead when it covers TIE_COVERAGE more than
    the best. A single start (an ``init``, every step of ``pcmapq track``) is refined without
    scoring: there is no choice to make. ``finals_out``, given, receives the finalists scored
    after the fine stages, best first, then every start scored after the rough one."""
    if len(starts) == 1:
        return fine(rough(starts[0]))
    firsts = sorted((scored(rough(s)) for s in starts), key=_rank)
    chosen = firsts[:finalists]
    for r in firsts[finalists:]:
        if support(r) >= CLOSE_FINALISTS * support(firsts[0]) and \
                not any(same_pose(r.transform, c.transform) for c in chosen):
            chosen.append(r)
    finals = sorted((scored(fine(r.transform)) for r in chosen), key=_rank)
    if finals_out is not None:
        finals_out.extend(finals + firsts)
    if covered is None:
        return finals[0].transform
    tied = [f.transform for f in finals if f.fitness >= finals[0].fitness - TIE_FITNESS]
    if len(tied) == 1:
        return tied[0]
    shares = [covered(tf) for tf in tied]
    most = int(np.argmax(shares))
    return tied[most] if shares[most] >= shares[0] + TIE_COVERAGE else tied[0]


def same_pose(a: Similarity2D, b: Similarity2D) -> bool:
    """Whether two poses are one for the choice of finalists: within SAME_POSE_M of
    translation and SAME_POSE_DEG of yaw."""
    turn = abs(np.degrees(wrapped(a.yaw - b.yaw)))
    return bool(np.hypot(a.tx - b.tx, a.ty - b.ty) < SAME_POSE_M and turn < SAME_POSE_DEG)


def support(a: Scored) -> float:
    """What a pose's score rests on, [0, 1]: its fitness, times exp(-PENALTY x what the map's
    free space costs the pose) where the map has free space
    (:func:`~pcmapq.align.free_space.cost`)."""
    return a.fitness * float(np.exp(-PENALTY * cost(a.contradiction, a.free_on_truth)))


def _rank(a: Scored) -> tuple[float, float]:
    """Sort key: higher support first, then lower RMSE."""
    return -support(a), a.rmse_m
