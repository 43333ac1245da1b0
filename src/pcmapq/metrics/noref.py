"""No-reference 3D map metrics: Mean Map Entropy (MME), Mean Plane Variance (MPV) and the
Mutually Orthogonal Metric (MOM), computed exactly as the ``map-metrics`` package
(MobileRoboticsSkoltech/map-metrics, Python 0.0.4 and its C++ rewrite) defines them.

The neighbourhood of a point q is every map point p with |p - q| < radius (strictly, as Open3D's
``search_radius_vector_3d``), the point itself included; there is no cap on the number of
neighbours. Covariances are unbiased (divided by n - 1, as ``np.cov``). Units: points and radius
in metres, MPV and MOM in square metres, MME in nats (ln of metres).

The map's neighbourhood sums come from :mod:`pcmapq.metrics.ballsums` (columns of side
``radius`` and a loop over candidates compiled by Numba, each decided exactly as Open3D's search
does), never a Python loop over points; memory stays bounded whatever the map's size, and each
point's sums are of its neighbours' offsets from it. The neighbourhoods of MOM's few query points
come from SciPy kd-trees.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.bounds import bounds
from pcmapq.metrics.ballsums import CHUNK_POINTS, ball_sums, moments

# the presets, re-exported: their home is apart from this module (which loads SciPy and Numba)
from pcmapq.metrics.defaults import DEPTH_RADIUS as DEPTH_RADIUS
from pcmapq.metrics.defaults import LIDAR_RADIUS, MIN_KNN
from pcmapq.metrics.defaults import MAX_NN as MAX_NN

#: MOM keeps an orthogonal-subset point whose neighbourhood holds more than this many map
#: points (hard-coded in map-metrics, independent of ``min_knn``).
MOM_MIN_NEIGHBOURS = 3
#: Pairs of query and map point that MOM's sums hold at once (:func:`_ball_sums`).
CHUNK_PAIRS = 100_000
#: The seed of a sampled pass's draw (:func:`sample_of`).
SAMPLE_SEED = 0
#: ln(2 pi e): MME's constant per dimension.
LN_2PIE = math.log(2.0 * math.pi * math.e)


@dataclass(frozen=True)
class NoRefScores:
    """MME (nats) and MPV (m^2) of one map, with the number of points each mean is over (NaN
    when that number is 0: a mean over no point is no figure).

    mme_points: points with more than ``min_knn`` neighbours and a positive determinant;
    mpv_points: points with more than ``min_knn`` neighbours; total_points: the map's size.
    flat: per point, whether its neighbourhood is flat (:func:`flat`), when asked for; else
    None (sampled: False for the points not drawn).
    sampled_points: the points the means are over when drawn at random (:func:`scores`'
    ``sample``), else None; mme_se, mpv_se: then the standard errors of the two means (nats,
    m^2), else None.
    """

    mme: float
    mpv: float
    mme_points: int
    mpv_points: int
    total_points: int
    flat: np.ndarray | None = None
    sampled_points: int | None = None
    mme_se: float | None = None
    mpv_se: float | None = None


def strict_radius(radius: float) -> float:
    """The largest r' whose square is below ``radius``^2, so that SciPy's inclusive test
    d^2 <= r'^2 keeps the pairs with d^2 < radius^2 (Open3D's strict test). The two agree
    except for a squared distance between r'^2 and radius^2 when no double squares to the
    double just below radius^2: an interval of one or two units in the last place (a point at
    exactly sqrt(2) from another with ``radius=math.sqrt(2)``, say), which real clouds do not
    meet."""
    if not radius > 0:
        raise ValueError(f"radius must be positive, got {radius}")
    target = np.nextafter(radius * radius, 0.0)
    r = math.sqrt(target)
    while r * r > target:
        r = np.nextafter(r, 0.0)
    while np.nextafter(r, np.inf) ** 2 <= target:
        r = np.nextafter(r, np.inf)
    return float(r)


def covariances(sums: np.ndarray) -> np.ndarray:
    """(N, 10) moment sums (count first) -> (N, 3, 3) unbiased covariances, m^2 (NaN where
    the count is below 2)."""
    n = sums[:, 0]
    mean = sums[:, 1:4] / n[:, None]
    second = np.empty((len(sums), 3, 3))
    for k, (a, b) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
        second[:, a, b] = second[:, b, a] = sums[:, 4 + k]
    with np.errstate(invalid="ignore", divide="ignore"):
        cov = (second - n[:, None, None] * mean[:, :, None] * mean[:, None, :]) / (n - 1)[:, None,
                                                                                         None]
    return cov


def _ball_sums(tree: cKDTree, queries: np.ndarray, r: float,
               chunk_pairs: int = CHUNK_PAIRS) -> np.ndarray:
    """(Q, 10) moment sums (see :func:`~pcmapq.metrics.ballsums.moments`) of ``tree``'s points
    within r (inclusive) of each query, added in the order of the points' indices; queries are
    taken a few at a time so that no more than about ``chunk_pairs`` pairs are held at once
    (the figures do not depend on it)."""
    counts = tree.query_ball_point(queries, r, return_length=True)
    sums = np.zeros((len(queries), 10))
    cuts = np.searchsorted(np.cumsum(counts), np.arange(chunk_pairs, int(counts.sum()),
                                                          chunk_pairs), side="right")
    for lo, hi in itertools.pairwise([0, *np.unique(cuts).tolist(), len(queries)]):
        if lo == hi or not counts[lo:hi].any():
            continue
        d = cKDTree(queries[lo:hi]).sparse_distance_matrix(tree, r, output_type="ndarray")
        order = np.lexsort((d["j"], d["i"]))
        rows, cols = d["i"][order], d["j"][order]
        del d, order
        starts = np.flatnonzero(np.r_[True, rows[1:] != rows[:-1]])
        sums[lo + rows[starts]] = np.add.reduceat(moments(tree.data[cols]), starts, axis=0)
    return sums


def neighbourhood_sums(points: np.ndarray, radius: float, chunk_points: int = CHUNK_POINTS,
                       workers: int | None = None, queries: np.ndarray | None = None
                       ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Yield (indices into ``points``, (k, 10) moment sums) over every point's neighbourhood:
    count, sums of x, y, z and of the products xx, xy, xz, yy, yz, zz, in coordinates relative
    to an origin of each point's own (covariances: :func:`covariances`). Chunks of about
    ``chunk_points`` points; order and figures are the same bit for bit whatever ``workers``
    (threads). ``queries``: only these points' neighbourhoods (indices into ``points``)."""
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got {pts.shape}")
    if not radius > 0:
        raise ValueError(f"radius must be positive, got {radius}")
    yield from ball_sums(pts, radius, chunk_points, workers, queries)


def entropies(cov: np.ndarray) -> np.ndarray:
    """0.5 ln det(2 pi e Sigma) per (3, 3) covariance (nats); NaN where the determinant is not
    positive (map-metrics skips those points)."""
    det = np.linalg.det(2.0 * np.pi * np.e * cov)
    out = np.full(len(cov), np.nan)
    ok = det > 0
    out[ok] = 0.5 * np.log(det[ok])
    return out


def plane_variances(cov: np.ndarray) -> np.ndarray:
    """Smallest eigenvalue of each (3, 3) covariance, m^2."""
    return np.linalg.eigvalsh(cov)[:, 0]


def flat(sums: np.ndarray) -> np.ndarray:
    """Per row of moment sums (see :func:`neighbourhood_sums`), whether the neighbourhood is
    flat as map-metrics' planar points are: more than 3 points, and of its covariance's
    eigenvalues 100 * lambda_0 < lambda_1."""
    ok = sums[:, 0] > 3
    out = np.zeros(len(sums), dtype=bool)
    lam = np.linalg.eigvalsh(covariances(sums[ok]))
    out[ok] = 100.0 * lam[:, 0] < lam[:, 1]
    return out


def sample_of(count: int, size: int) -> np.ndarray | None:
    """Sorted indices of ``size`` of ``count`` points drawn at random without replacement
    (seeded: the same draw every run), or None when ``size`` is 0 or not below ``count``."""
    if size <= 0 or size >= count:
        return None
    return np.sort(np.random.default_rng(SAMPLE_SEED).choice(count, size, replace=False))


def _standard_error(values: np.ndarray, population: int) -> float:
    """Standard error of the mean of ``values``, drawn without replacement from ``population``
    (finite-population correction)."""
    n = len(values)
    if n < 2:
        return math.nan
    return float(np.sqrt(np.var(values, ddof=1) / n * (1.0 - n / population)))


def scores(points: np.ndarray, radius: float = LIDAR_RADIUS, min_knn: int = MIN_KNN,
           chunk_points: int = CHUNK_POINTS, workers: int | None = None,
           with_flat: bool = False, sample: int = 0) -> NoRefScores:
    """MME and MPV of a map (N, 3 metres) in one pass: the means, over the points with more than
    ``min_knn`` neighbours (itself included) closer than ``radius`` metres, of the entropy
    0.5 ln det(2 pi e Sigma) (points with det <= 0 skipped) and of Sigma's smallest
    eigenvalue. NaN when no point qualifies (map-metrics gives 0.0, a figure better than any
    map's: pcmapq reports none). ``with_flat``: also which points'
    neighbourhoods are flat (:func:`flat`), from the same pass (MOM's subset extraction needs
    them). ``sample``: the means over that many points drawn at random (:func:`sample_of`),
    each with its whole neighbourhood in the map, and their standard errors (0: every point).
    """
    queries = sample_of(len(points), sample)
    ent_sum = var_sum = 0.0
    ent_n = var_n = 0
    entropy, variance = [], []  # per point, kept when sampled
    flat_points = np.zeros(len(points), dtype=bool) if with_flat else None
    for idx, sums in neighbourhood_sums(points, radius, chunk_points, workers, queries):
        if flat_points is not None:
            flat_points[idx] = flat(sums)
        cov = covariances(sums[sums[:, 0] > min_knn])
        ent = entropies(cov)
        ent, var = ent[~np.isnan(ent)], plane_variances(cov)
        ent_sum, ent_n = ent_sum + float(ent.sum()), ent_n + len(ent)
        var_sum, var_n = var_sum + float(var.sum()), var_n + len(var)
        if queries is not None:
            entropy.append(ent)
            variance.append(var)
    sampled = None if queries is None else len(queries)
    se = (None, None) if sampled is None else (
        _standard_error(np.concatenate(entropy), len(points)),
        _standard_error(np.concatenate(variance), len(points)))
    return NoRefScores(mme=ent_sum / ent_n if ent_n else math.nan,
                       mpv=var_sum / var_n if var_n else math.nan,
                       mme_points=ent_n, mpv_points=var_n, total_points=len(points),
                       flat=flat_points, sampled_points=sampled, mme_se=se[0], mpv_se=se[1])


def mme(points: np.ndarray, radius: float = LIDAR_RADIUS, min_knn: int = MIN_KNN) -> float:
    """Mean Map Entropy, nats (see :func:`scores`)."""
    return scores(points, radius, min_knn).mme


def mpv(points: np.ndarray, radius: float = LIDAR_RADIUS, min_knn: int = MIN_KNN) -> float:
    """Mean Plane Variance, m^2 (see :func:`scores`)."""
    return scores(points, radius, min_knn).mpv


def query_covariances(points: np.ndarray, queries: np.ndarray,
                      radius: float) -> tuple[np.ndarray, np.ndarray]:
    """For each query (Q, 3 metres): its number of map points closer than ``radius`` and their
    unbiased covariance (Q, 3, 3), m^2. Only the map points near the queries are indexed."""
    q = np.asarray(queries, dtype=np.float64).reshape(-1, 3)
    pts = np.asarray(points, dtype=np.float64)
    if len(q) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3, 3))
    r = strict_radius(radius)
    lo, hi = bounds(q)
    lo, hi = lo - radius, hi + radius
    near = pts[np.all((pts >= lo) & (pts <= hi), axis=1)]
    if len(near) == 0:
        return np.zeros(len(q), dtype=np.int64), np.full((len(q), 3, 3), np.nan)
    origin = q.mean(axis=0)
    near -= origin
    sums = _ball_sums(cKDTree(near), q - origin, r)
    return sums[:, 0].astype(np.int64), covariances(sums)


def mom(points: np.ndarray, orth_subset: Sequence[np.ndarray], radius: float = LIDAR_RADIUS,
        min_neighbours: int = MOM_MIN_NEIGHBOURS) -> float:
    """Mutually Orthogonal Metric, m^2: for each plane of ``orth_subset`` (arrays of points in
    the map's frame, metres), the median over its points with more than ``min_neighbours`` map
    points closer than ``radius`` of the neighbourhood's smallest covariance eigenvalue; the
    sum of those medians (NaN for a plane with no such point, as ``np.median([])``)."""
    sizes = [len(plane) for plane in orth_subset]
    if not sizes:
        return 0.0
    counts, cov = query_covariances(points, np.concatenate([np.asarray(p, dtype=np.float64)
                                                           .reshape(-1, 3)
                                                           for p in orth_subset]), radius)
    total = 0.0
    for part in np.split(np.arange(sum(sizes)), np.cumsum(sizes)[:-1]):
        values = plane_variances(cov[part][counts[part] > min_neighbours])
        total += float(np.median(values)) if len(values) else math.nan
    return total
