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
