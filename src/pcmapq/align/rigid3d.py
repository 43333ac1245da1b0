"""3D rigid registration of two point clouds with no initial guess: FPFH features + RANSAC,
then point-to-plane ICP.

Frames: the result ``T`` (4x4) takes source points to the target frame,
``p_target = T @ p_source``; metres. Both clouds are first moved to their centroids (voxel keys
stay small and sums precise with UTM coordinates); ``T`` is given back in the input frames.

1. Both clouds are voxel-downsampled at ``voxel`` (centroid per cell, numpy, deterministic
   order).
2. Global (:mod:`pcmapq.align.features3d`, skipped when ``init`` is given): FPFH at no more
   than 8,000 evenly spread points per cloud, matched as mutual nearest neighbours in feature
   space, then Open3D's RANSAC on those matches, seeded and on one thread. Where that guess
   puts less than GUESS_FIT of the source within 1.5 ``voxel`` of the target, a ``second``
   guess, when one is given (the plans' 2D search, :mod:`pcmapq.align.plan_guess`), is asked
   for, and the one that fits more of the source is refined.
3. ICP (:mod:`pcmapq.align.refine3d`): small_gicp's point-to-plane ICP on one thread, three
   stages with correspondence distances 2, 1 and 0.5 ``voxel`` (the last on clouds downsampled
   at ``voxel / 2``).
4. Scores: ``fitness`` is the share of the source (downsampled at ``voxel / 2``) within
   ``tolerance`` (default ``voxel``) of the target (downsampled at ``voxel / 4``), ``rmse_m`` the
   RMSE of those inlier distances, metres.

Repeated runs give identical results. Cost grows with the clouds; on outdoor maps a ``voxel`` of
0.5-1 m is the practical choice (docs/benchmarks.md, "3D registration").
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.align.refine3d import refine
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.transform import affine
from pcmapq.core.voxels import voxel_centroids

__all__ = ["Registration3D", "align_3d"]

#: Fewest points left after downsampling for features to mean anything.
MIN_POINTS = 10
#: Share of the source a global guess must put near the target (within 1.5 ``voxel``, as its
#: RANSAC counts inliers) for no second guess to be asked for.
GUESS_FIT = 0.5


class Registration3D(NamedTuple):
    """transform: 4x4 source -> target. fitness: share of source points within the tolerance
    of the target, [0, 1]. rmse_m: RMSE of those inlier distances, metres. Unpacks as a tuple."""

    transform: np.ndarray
    fitness: float
    rmse_m: float


def align_3d(source_xyz: np.ndarray, target_xyz: np.ndarray, *, voxel: float = 0.3,
             init: np.ndarray | None = None, tolerance: float | None = None,
             second: Callable[[], np.ndarray | None] | None = None) -> Registration3D:
    """Register ``source_xyz`` (N, 3) to ``target_xyz`` (M, 3), metres: ``p_target = T p_source``.

    voxel: working resolution, metres (features, RANSAC and ICP distances scale with it).
    init: 4x4 initial guess; skips the global search (ICP still refines). tolerance: fitness
    distance, metres (default ``voxel``). second: another global guess (4x4, source ->
    target; None: it has none), asked for only when the global search's fits less than
    GUESS_FIT of the source; the better fitting of the two is refined. Points that are not
    finite, or exactly (0, 0, 0) (a common no-return marker), are ignored. Deterministic.
    """
    if not voxel > 0:
        raise InputError(f"voxel must be positive, got {voxel}")
    source = _usable(source_xyz, "source")
    target = _usable(target_xyz, "target")
    src_shift, tgt_shift = _translation(-source.mean(axis=0)), _translation(-target.mean(axis=0))
    source, target = _shifted(source, src_shift), _shifted(target, tgt_shift)
    src_down, tgt_down = voxel_centroids(source, voxel), voxel_centroids(target, voxel)
    if len(src_down) < MIN_POINTS or len(tgt_down) < MIN_POINTS:
        raise EvaluationError(f"too few points at voxel {voxel} m to register "
                              f"({len(src_down)} source, {len(tgt_down)} target)")
    if init is None:
        from pcmapq.align.features3d import global_registration  # Open3D: loaded when it runs

        guess = global_registration(src_down, tgt_down, voxel)
        if second is not None:
            guess = _better(guess, second, src_down, tgt_down, voxel, (src_shift, tgt_shift))
    else:
        guess = tgt_shift @ np.asarray(init, dtype=np.float64).reshape(4, 4) @ np.linalg.inv(
            src_shift)
    levels = {1.0: (src_down, tgt_down)}
    transform = refine(source, target, guess, voxel, levels)
    half = levels.get(0.5, (None, None))[0]  # the last ICP stage's source, when at voxel / 2
    fitness, rmse = score(source, target, transform, tolerance or voxel, voxel / 2, half)
    return Registration3D(np.linalg.inv(tgt_shift) @ transform @ src_shift, fitness, rmse)


def _better(guess: np.ndarray, second: Callable[[], np.ndarray | None], source: np.ndarray,
            target: np.ndarray, voxel: float, shifts: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """``guess`` (4x4, between the centred clouds ``source`` and ``target``, both downsampled
    at ``voxel``), or ``second()`` (in the input frames; ``shifts``: each cloud's centring) when
    the first fits less than GUESS_FIT of the source and the second fits more."""
    tree = cKDTree(target)

    def fit(transform: np.ndarray) -> float:
        dist, _ = tree.query(apply(transform, source), distance_upper_bound=1.5 * voxel,
                             workers=-1)
        return float(np.isfinite(dist).mean())

    first = fit(guess)
    if first >= GUESS_FIT:
        return guess
    other = second()
    if other is None:
        return guess
    src_shift, tgt_shift = shifts
    other = tgt_shift @ np.asarray(other, dtype=np.float64) @ np.linalg.inv(src_shift)
    return other if fit(other) > first else guess


def score(source: np.ndarray, target: np.ndarray, transform: np.ndarray, tolerance: float,
          voxel: float, source_down: np.ndarray | None = None) -> tuple[float, float]:
    """(fitness, rmse): share of the source (downsampled at ``voxel``; ``source_down``: already
    so) moved by ``transform`` within ``tolerance`` metres of the target (downsampled at
    ``voxel / 2``), and the RMSE of those distances, metres."""
    down = voxel_centroids(source, voxel) if source_down is None else source_down
    moved = apply(transform, down)
    tree = cKDTree(voxel_centroids(target, voxel / 2))
    dist, _ = tree.query(moved, distance_upper_bound=tolerance, workers=-1)
    inliers = dist[np.isfinite(dist)]
    fitness = len(inliers) / len(moved) if len(moved) else 0.0
    rmse = float(np.sqrt(np.mean(inliers**2))) if len(inliers) else 0.0
    return float(fitness), rmse


def apply(transform: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``transform`` (4x4) applied to points (N, 3)."""
    return affine(points, transform)


def _translation(offset: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = offset
    return out


def _shifted(points: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """``points`` (N, 3, this module's own copy) moved by the translation ``shift`` (4x4) in
    place: the numbers :func:`apply` gives, without a second copy of all the points."""
    points += shift[:3, 3]
    return points


def _usable(xyz: np.ndarray, name: str) -> np.ndarray:
    """(N, 3) float64 finite points, without exact (0, 0, 0) rows: a copy of its own, made
    once (a float32 cloud, mapped onto its file, is converted straight into it)."""
    points = np.asarray(xyz)
    if points.ndim != 2 or points.shape[1] != 3:
        raise InputError(f"{name}: expected N x 3 points, got shape {points.shape}")
    keep = np.isfinite(points).all(axis=1) & (points != 0.0).any(axis=1)
    if not keep.any():
        raise InputError(f"{name}: no usable points")
    return np.array(points, dtype=np.float64) if keep.all() else \
        np.asarray(points[keep], dtype=np.float64)
