"""One-to-one matching of map features to truth features, and the paper's quality q.

The detector proposes candidate pairs within the metric threshold (see each detector's
``candidates``); only pairs with at least one strong feature are candidates, so a strong feature
may be confirmed by a support-level one on the other side, but two support-level features never
match. One optimal assignment is then solved over the candidate graph, per connected component
(scipy ``linear_sum_assignment``): it maximises the sum over chosen pairs of
``weight * (1 - cost)``, where weight is the pair's number of strong features (1 or 2) and cost
the detector's normalised cost in [0, 1]. A pair is worth its closeness: the assignment never
trades one close pair for two stretched ones just to match more features (which would report
displacements larger than the walls' true offset), and a strong-strong pair beats a strong-weak
one.

quality = matched strong truth / strong truth features (the paper's q = RMF / GTF);
precision = matched strong map / strong map features; f1 = their harmonic mean. A ratio with
nothing to count (no strong feature on that side) is undefined, None, not 0: a round room has no
corner, and its perfect map must not score 0 for missing none. So are all three when the truth
has fewer features than the detector needs to have anything to find (rooms: a place of one room
has no rooms to tell apart), or none of the kind it finds (rooms: a street's walls close off
pockets, not rooms). f1 is None when either is None, 0 when both are 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse
from scipy.optimize import linear_sum_assignment
from scipy.sparse.csgraph import connected_components

from pcmapq.core.words import count
from pcmapq.features import Features, detector
from pcmapq.features.names import MATCH_THRESHOLD


@dataclass(frozen=True)
class Matching:
    """The matched pairs of one detector and the scores they give.

    truth_idx, map_idx: (M,) indices of matched pairs, sorted by truth index.
    displacement: (M, 2) metres, from the truth feature to its map feature (the paper's
        "vectorial map"), in the truth/map metric frame.
    cost: (M,) the detector's normalised cost of each pair, [0, 1].
    quality: matched strong truth / strong truth features (the paper's q), in [0, 1]; None
        when there is no strong truth feature.
    precision: matched strong map / strong map features, in [0, 1]; None when there is no
        strong map feature.
    f1: harmonic mean of quality and precision; 0 when both are 0, None when either is None.
    truth_features, map_features: numbers of strong truth and strong map features.
    matched: number of strong truth features matched (quality's numerator).
    matched_map: number of strong map features matched (precision's numerator).
    missing: indices of strong truth features left unmatched.
    extra: indices of strong map features left unmatched.
    unscored: why the detector had nothing to find (the truth has fewer features than it
        needs, :attr:`~pcmapq.features.base.Detector.min_truth`, or none of the kind it finds,
        :attr:`~pcmapq.features.base.Detector.nothing_to_find`): its three scores are None.
    """

    truth_idx: np.ndarray
    map_idx: np.ndarray
    displacement: np.ndarray
    cost: np.ndarray
    quality: float | None
    precision: float | None
    f1: float | None
    truth_features: int
    map_features: int
    matched: int
    matched_map: int
    missing: np.ndarray
    extra: np.ndarray
    unscored: str | None = None

    def note(self, truth_scope: str = "") -> str | None:
        """Why a score is undefined, one line (None when all three are defined);
        ``truth_scope`` qualifies the truth's features, e.g. "inside the footprint"."""
        if self.unscored is not None:
            return self.unscored
        scope = f" {truth_scope}" if truth_scope else ""
        reasons = ([f"no strong truth feature{scope}"] if self.quality is None else []) + \
                  (["no strong map feature"] if self.precision is None else [])
        return "; ".join(reasons) or None


def assign(i: np.ndarray, j: np.ndarray, cost: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Optimal one-to-one selection among candidate pairs.

    Parameters
    ----------
    i, j : (K,) left and right node indices of the candidate pairs (no duplicate pairs).
    cost : (K,) normalised pair costs in [0, 1], lower is better.
    weight : (K,) int weight of each pair (here: its number of strong features); the sum of
        ``weight * (1 - cost)`` over the chosen pairs is maximised.

    Returns
    -------
    (K,) bool mask of the selected pairs.
    """
    chosen = np.zeros(len(i), dtype=bool)
    if len(i) == 0:
        return chosen
    # nodes: left i -> i, right j -> n_left + j; components of the candidate graph
    left, li = np.unique(i, return_inverse=True)
    right, rj = np.unique(j, return_inverse=True)
    n = len(left) + len(right)
    graph = sparse.coo_array((np.ones(len(i)), (li, len(left) + rj)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    comp = label[li]
    # a component with one pair is that pair
    sizes = np.bincount(comp)
    single = sizes[comp] == 1
    chosen[single] = True
    for c in np.unique(comp[~single]):
        k = np.flatnonzero(comp == c)
        chosen[k[_assign_component(li[k], rj[k], cost[k], weight[k])]] = True
    return chosen


def _assign_component(i: np.ndarray, j: np.ndarray, cost: np.ndarray,
                      weight: np.ndarray) -> np.ndarray:
    """:func:`assign` on one connected component (dense, exact). Returns the chosen pair
    positions."""
    rows, ri = np.unique(i, return_inverse=True)
    cols, cj = np.unique(j, return_inverse=True)
    # every candidate keeps a small positive score, so a pair at the threshold still matches
    score = weight * (1.0 - 0.999 * np.clip(cost, 0.0, 1.0))
    matrix = np.zeros((len(rows), len(cols)))
    matrix[ri, cj] = score
    r, c = linear_sum_assignment(matrix, maximize=True)
    picked = np.full((len(rows), len(cols)), -1, dtype=np.int64)
    picked[ri, cj] = np.arange(len(i))
    sel = picked[r, c]
    return sel[sel >= 0]


def _ratio(num: int, den: int) -> float | None:
    """num / den; None (undefined, not 0) when there is nothing to count."""
    return float(num) / den if den > 0 else None


def harmonic_mean(quality: float | None, precision: float | None) -> float | None:
    """f1 of a quality and a precision: None when either is None, 0 when both are 0."""
    if quality is None or precision is None:
        return None
    return 2 * quality * precision / (quality + precision) if quality + precision > 0 else 0.0


def match(name: str, truth: Features, map_: Features, threshold: float = MATCH_THRESHOLD,
          params: Any = None) -> Matching:
    """Match ``map_`` features to ``truth`` features of detector ``name``, one to one.

    Parameters
    ----------
    name : detector name, a key of :data:`pcmapq.features.DETECTORS`.
    truth, map_ : features of the truth and of the map, in the same metric frame (metres).
    threshold : largest distance between matched features, metres (its exact meaning is the
        detector's: point distance, or perpendicular offset of segments for Hough).
    params : the detector's parameters (its ``Params``), whose matching rule applies; None: its
        defaults.

    Returns
    -------
    The :class:`Matching`.
    """
    found = detector(name)
    i, j, cost, disp = found.candidates(truth, map_, threshold, found.checked(params))
    weight = truth.strong[i].astype(np.int64) + map_.strong[j].astype(np.int64)
    keep = weight > 0
    i, j, cost, disp, weight = i[keep], j[keep], cost[keep], disp[keep], weight[keep]
    chosen = assign(i, j, np.asarray(cost, dtype=np.float64), weight)
    order = np.argsort(i[chosen], kind="stable")
    ti, mj = i[chosen][order], j[chosen][order]
    t_strong, m_strong = np.flatnonzero(truth.strong), np.flatnonzero(map_.strong)
    matched = int(truth.strong[ti].sum())
    matched_map = int(map_.strong[mj].sum())
    quality = _ratio(matched, len(t_strong))
    precision = _ratio(matched_map, len(m_strong))
    unscored = None
    if len(truth) < found.min_truth:  # nothing to find: undefined, not 0
        unscored = (f"the truth has {count(len(truth), found.noun)}, fewer than "
                    f"{found.min_truth}: nothing to find")
    else:
        unscored = found.nothing_to_find(truth)
    if unscored is not None:
        quality = precision = None
    return Matching(
        truth_idx=ti,
        map_idx=mj,
        displacement=np.asarray(disp, dtype=np.float64)[chosen][order].reshape(-1, 2),
        cost=np.asarray(cost, dtype=np.float64)[chosen][order],
        quality=quality,
        precision=precision,
        f1=harmonic_mean(quality, precision),
        truth_features=len(t_strong),
        map_features=len(m_strong),
        matched=matched,
        matched_map=matched_map,
        missing=np.setdiff1d(t_strong, ti),
        extra=np.setdiff1d(m_strong, mj),
        unscored=unscored,
    )
