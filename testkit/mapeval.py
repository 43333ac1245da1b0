"""MapEval's AWD and SCS written plainly, one voxel at a time, as Cloud_Map_Evaluation's
``MapEval::calculateVMD`` defines them with the closed-form 2-Wasserstein distance of
docs/metrics.md (SciPy's matrix square root): the reference that the vectorised
:mod:`pcmapq.metrics.map_gaussians` is tested against. Slow: for clouds of a few thousand
points."""

from __future__ import annotations

import math
import statistics

import numpy as np
from scipy.linalg import sqrtm

Key = tuple[int, int, int]


def reference_awd_scs(map_xyz: np.ndarray, truth_xyz: np.ndarray, voxel: float = 3.0,
                      min_points: int = 100, radius: int = 5
                      ) -> tuple[float | None, float | None, int]:
    """(AWD metres, SCS, voxels compared) of two clouds (N, 3) in one frame, metres."""
    est, gt = _gaussians(map_xyz, voxel, min_points), _gaussians(truth_xyz, voxel, min_points)
    w = {key: _w2(*gt[key], *est[key]) for key in est if key in gt}
    if not w:
        return None, None, 0
    terms = []
    for (x, y, z) in w:
        around = [w[(x + dx, y + dy, z + dz)]
                  for dx in range(-radius, radius + 1) for dy in range(-radius, radius + 1)
                  for dz in range(-radius, radius + 1)
                  if (dx, dy, dz) != (0, 0, 0) and (x + dx, y + dy, z + dz) in w]
        if around:
            mean = statistics.fmean(around)
            terms.append(statistics.pstdev(around) / mean if mean > 0 else 0.0)
    return statistics.fmean(w.values()), statistics.fmean(terms) if terms else None, len(w)


def _gaussians(points: np.ndarray, voxel: float, min_points: int
               ) -> dict[Key, tuple[np.ndarray, np.ndarray]]:
    """Each voxel holding at least ``min_points`` points: their mean and sample covariance."""
    cells: dict[Key, list[np.ndarray]] = {}
    for p in np.asarray(points, dtype=np.float64):
        key = (math.floor(p[0] / voxel), math.floor(p[1] / voxel), math.floor(p[2] / voxel))
        cells.setdefault(key, []).append(p)
    out = {}
    for key, members in cells.items():
        if len(members) >= min_points:
            a = np.array(members)
            out[key] = (a.mean(axis=0), np.cov(a.T, ddof=1))
    return out


def _w2(mean_a: np.ndarray, cov_a: np.ndarray, mean_b: np.ndarray, cov_b: np.ndarray) -> float:
    """W2 between two Gaussians, covariance eigenvalues first raised to 1e-6 m^2."""
    a, b = _floor(cov_a), _floor(cov_b)
    root = np.real(sqrtm(a))
    cross = float(np.trace(np.real(sqrtm(root @ b @ root))))
    squared = float(np.sum((mean_a - mean_b) ** 2)) + np.trace(a) + np.trace(b) - 2 * cross
    return math.sqrt(max(squared, 0.0))


def _floor(cov: np.ndarray) -> np.ndarray:
    value, vector = np.linalg.eigh(cov)
    return vector @ np.diag(np.maximum(value, 1e-6)) @ vector.T


def mapeval_as_coded(map_xyz: np.ndarray, truth_xyz: np.ndarray, voxel: float = 3.0,
                     min_points: int = 100, radius: int = 5
                     ) -> tuple[float | None, float | None, int]:
    """(AWD, SCS, voxels) with Cloud_Map_Evaluation's arithmetic as its code does it
    (docs/metrics.md): each voxel's covariance the sample covariance over (n - 1)^2 (its scatter
    matrix divided by n - 1 three times), eigenvalues raised to 1e-6 m^2, the square-root term
    the trace of a Cholesky factor of ``L_t B L_t^T`` (``L_t`` the truth covariance's), and a
    neighbourhood whose mean distance is 0 giving NaN. The sums of each voxel come from
    pcmapq's :func:`~pcmapq.metrics.map_gaussians.voxel_gaussians` (for large maps)."""
    from pcmapq.core.voxels import voxel_keys
    from pcmapq.metrics.map_gaussians import voxel_gaussians

    corner = np.floor(np.minimum(map_xyz.min(axis=0), truth_xyz.min(axis=0)) / voxel) * voxel
    sides = []
    for cloud in (map_xyz - corner, truth_xyz - corner):
        keys, mean, cov = voxel_gaussians(cloud, voxel, min_points)
        counts = dict(zip(*np.unique(voxel_keys(cloud, voxel), return_counts=True),
                          strict=True))
        sides.append({int(k): (m, c / (counts[k] - 1) ** 2) for k, m, c in zip(
            keys, mean, cov, strict=True)})
    est, gt = sides
    w = {key: _w2_as_coded(*gt[key], *est[key]) for key in est if key in gt}
    if not w:
        return None, None, 0
    bits, mask = 21, (1 << 21) - 1
    index = {key: ((key >> 2 * bits) & mask, (key >> bits) & mask, key & mask) for key in w}
    at = {v: w[k] for k, v in index.items()}
    terms = []
    for (x, y, z) in at:
        around = [at[(x + dx, y + dy, z + dz)]
                  for dx in range(-radius, radius + 1) for dy in range(-radius, radius + 1)
                  for dz in range(-radius, radius + 1)
                  if (dx, dy, dz) != (0, 0, 0) and (x + dx, y + dy, z + dz) in at]
        if around:
            mean = statistics.fmean(around)
            terms.append(statistics.pstdev(around) / mean if mean > 0 else math.nan)
    return statistics.fmean(w.values()), statistics.fmean(terms) if terms else None, len(w)


def _w2_as_coded(mean_t: np.ndarray, cov_t: np.ndarray, mean_m: np.ndarray,
                 cov_m: np.ndarray) -> float:
    """``VoxelCalculator::computeWassersteinDistanceGaussian(gt, est)``."""
    a, b = _floor(cov_t), _floor(cov_m)
    factor = np.linalg.cholesky(a)
    cross = np.trace(np.linalg.cholesky(factor @ b @ factor.T))
    squared = float(np.sum((mean_t - mean_m) ** 2)) + np.trace(a + b) - 2 * cross
    return math.sqrt(max(squared, 0.0))
