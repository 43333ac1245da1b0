"""2D alignment of a map to the truth: a global raster search, then ICP.

Frames: ``Alignment.transform`` takes map-frame points to the truth frame,
``p_truth = s * R(yaw) * p_map + t`` (scale stays 1 here).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.align.coarse import auto_resolution, coarse_candidates
from pcmapq.align.icp import (
    DEFAULT_SCHEDULE,
    IcpTarget,
    refine_point_to_line,
    voxel_downsample,
)
from pcmapq.align.icp import refine as icp_refine
from pcmapq.align.transform import Similarity2D

__all__ = ["Alignment", "Similarity2D", "align", "score"]


@dataclass(frozen=True)
class Alignment:
    """The result of :func:`align`.

    transform: map frame -> truth frame. fitness: share of (voxel-downsampled) map points within
    ``tolerance_m`` of a truth point after alignment, [0, 1]. rmse_m: RMSE of those inlier
    distances, metres. method: "coarse+icp", "init+icp" or "none".
    """

    transform: Similarity2D
    fitness: float
    rmse_m: float
    tolerance_m: float
    method: str


def _score_tree(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D,
                tolerance: float) -> tuple[float, float]:
    """(fitness, rmse in metres) of the map (N, 2, map frame) against a truth KD-tree."""
    if len(map_xy) == 0:
        return 0.0, 0.0
    dist, _ = tree.query(tf.apply(map_xy), distance_upper_bound=tolerance)
    inliers = dist[np.isfinite(dist)]
    rmse = float(np.sqrt(np.mean(inliers**2))) if len(inliers) else 0.0
    return len(inliers) / len(map_xy), rmse


def score(map_xy: np.ndarray, truth_xy: np.ndarray, tf: Similarity2D,
          tolerance: float = 0.2) -> tuple[float, float]:
    """(fitness, rmse): the share of map points (N, 2, metres, map frame) that ``tf`` puts within
    ``tolerance`` metres of a truth point (M, 2, metres, truth frame), and the RMSE in metres of
    those inlier distances (0 when there are none)."""
    tree = cKDTree(np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2))
    return _score_tree(np.asarray(map_xy, dtype=np.float64).reshape(-1, 2), tree, tf, tolerance)


def align(map_xy: np.ndarray, truth_xy: np.ndarray, *, init: Similarity2D | None = None,
          refine: bool = True, tolerance: float = 0.2, voxel: float = 0.05,
          resolution: float | None = None, top_k: int = 6, finalists: int = 2) -> Alignment:
    """Align a map to the truth with no initial guess needed; never fails on a bad match (an
    empty map or truth gives fitness 0).

    map_xy: (N, 2) metres, map frame; truth_xy: (M, 2) metres, truth frame: occupied cell centres
    or wall-band points.
    init: a starting map -> truth transform; given, the global search is skipped and ICP starts
    there (its scale is dropped). refine: False with no ``init`` scores the identity ("none");
    False with ``init`` scores ``init`` as it is ("init").
    tolerance: inlier distance for fitness and RMSE, metres (default 0.2).
    voxel: both clouds are voxel-downsampled to this cell size, metres, before anything else;
    fitness and RMSE are measured on the downsampled clouds.
    resolution: raster cell size of the global search, metres (default: the map's radius / 40,
    at least 0.25). top_k: candidate poses of the global search, each refined by a first, coarse
    ICP stage; finalists: how many of those, by fitness, go through the fine ICP stages. The
    final pose with the highest fitness wins.
    """
    map_ds = voxel_downsample(map_xy, voxel)
    truth_ds = voxel_downsample(truth_xy, voxel)
    if len(map_ds) == 0 or len(truth_ds) == 0:
        return Alignment(Similarity2D() if init is None else init, 0.0, 0.0, tolerance, "none")
    tree = cKDTree(truth_ds)
    if not refine:
        tf = Similarity2D() if init is None else init
        return _result(map_ds, tree, tf, tolerance, "none" if init is None else "init")
    if init is not None:
        tf = icp_refine(map_ds, IcpTarget(truth_ds), init)
        tf = refine_point_to_line(map_ds, truth_ds, tf, DEFAULT_SCHEDULE[-1][0])
        return _result(map_ds, tree, tf, tolerance, "init+icp")
    resolution = auto_resolution(map_ds) if resolution is None else resolution
    starts = coarse_candidates(map_ds, truth_ds, resolution=resolution, top_k=top_k)
    (first_dist, first_voxel), *fine_stages = DEFAULT_SCHEDULE
    rough = IcpTarget(truth_ds, ((max(first_dist, 2 * resolution), first_voxel),))
    fine = IcpTarget(truth_ds, tuple(fine_stages))
    firsts = [_result(map_ds, tree, icp_refine(map_ds, rough, c.transform), tolerance, "")
              for c in starts]
    finals = [_result(map_ds, tree, icp_refine(map_ds, fine, r.transform), tolerance,
                      "coarse+icp") for r in sorted(firsts, key=_rank)[:finalists]]
    best = min(finals, key=_rank).transform
    best = refine_point_to_line(map_ds, truth_ds, best, DEFAULT_SCHEDULE[-1][0])
    return _result(map_ds, tree, best, tolerance, "coarse+icp")


def _rank(a: Alignment) -> tuple[float, float]:
    """Sort key: higher fitness first, then lower RMSE."""
    return -a.fitness, a.rmse_m


def _result(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D, tolerance: float,
            method: str) -> Alignment:
    """Score ``tf`` on the map against the truth tree."""
    fitness, rmse = _score_tree(map_xy, tree, tf, tolerance)
    return Alignment(tf, fitness, rmse, tolerance, method)
