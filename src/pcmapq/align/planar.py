"""2D alignment of a map to the truth with no initial guess: a global raster search
(:mod:`~pcmapq.align.coarse`), then ICP from its best candidates. ``Alignment.transform`` takes
map-frame points to the truth frame, ``p_truth = s * R(yaw) * p_map + t``."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.align.coarse import (
    auto_resolution,
    coarse_search,
    distinctiveness,
    similarity_resolution,
    similarity_search,
)
from pcmapq.align.point_to_line import refine_point_to_line
from pcmapq.align.point_to_point import DEFAULT_SCHEDULE, IcpTarget, refine_point_to_point
from pcmapq.align.similarity_icp import SimilarityTarget, refine_similarity, similarity_schedule
from pcmapq.transform import Similarity2D
from pcmapq.voxels import voxel_centroids


@dataclass(frozen=True)
class Alignment:
    """The result of :func:`align`.

    transform: map frame -> truth frame. fitness: share of (voxel-downsampled) map points within
    ``tolerance_m`` of a truth point after alignment, [0, 1]. rmse_m: RMSE of those inlier
    distances, metres. method: "coarse+icp", "similarity+icp" (global search over scale too),
    "init+icp", "init" or "none". distinctiveness: how far the final pose's score in the global
    search stands above the best score elsewhere, [0, 1] (see
    :func:`~pcmapq.align.coarse.distinctiveness`); None when there was no global search.
    """

    transform: Similarity2D
    fitness: float
    rmse_m: float
    tolerance_m: float
    method: str
    distinctiveness: float | None = None


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
          resolution: float | None = None, top_k: int = 6, finalists: int | None = None,
          scale: bool = False, scale_range: tuple[float, float] = (0.2, 5.0)) -> Alignment:
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
    ICP stage; finalists: how many of those, by fitness, go through the fine ICP stages (default
    2 rigid; 3 with ``scale``, where the rough stage ranks less surely: the Freiburg 079 map's
    right pose came third). The final pose with the highest fitness wins.
    scale: also estimate the scale, for a map in an unknown unit (see :func:`align_similarity`);
    scale_range: (lowest, highest) scale it may have, truth units per map unit.
    """
    if scale:
        return align_similarity(map_xy, truth_xy, init=init, refine=refine, tolerance=tolerance,
                                voxel=voxel, resolution=resolution, top_k=top_k,
                                finalists=finalists or 3, scale_range=scale_range)
    finalists = finalists or 2
    map_ds = voxel_centroids(map_xy, voxel)
    truth_ds = voxel_centroids(truth_xy, voxel)
    if len(map_ds) == 0 or len(truth_ds) == 0:
        return Alignment(Similarity2D() if init is None else init, 0.0, 0.0, tolerance, "none")
    tree = cKDTree(truth_ds)
    if not refine:
        tf = Similarity2D() if init is None else init
        return _result(map_ds, tree, tf, tolerance, "none" if init is None else "init")
    if init is not None:
        tf = refine_point_to_point(map_ds, IcpTarget(truth_ds), init)
        tf = refine_point_to_line(map_ds, truth_ds, tf, DEFAULT_SCHEDULE[-1][0])
        return _result(map_ds, tree, tf, tolerance, "init+icp")
    resolution = auto_resolution(map_ds) if resolution is None else resolution
    search = coarse_search(map_ds, truth_ds, resolution=resolution, top_k=top_k)
    starts = search.candidates
    (first_dist, first_voxel), *fine_stages = DEFAULT_SCHEDULE
    rough = IcpTarget(truth_ds, ((max(first_dist, 2 * resolution), first_voxel),))
    fine = IcpTarget(truth_ds, tuple(fine_stages))
    firsts = [_result(map_ds, tree, refine_point_to_point(map_ds, rough, c.transform),
                      tolerance, "") for c in starts]
    finals = [_result(map_ds, tree, refine_point_to_point(map_ds, fine, r.transform),
                      tolerance, "coarse+icp") for r in sorted(firsts, key=_rank)[:finalists]]
    best = min(finals, key=_rank).transform
    best = refine_point_to_line(map_ds, truth_ds, best, DEFAULT_SCHEDULE[-1][0])
    return replace(_result(map_ds, tree, best, tolerance, "coarse+icp"),
                   distinctiveness=distinctiveness(search, best))


def _rank(a: Alignment) -> tuple[float, float]:
    """Sort key: higher fitness first, then lower RMSE."""
    return -a.fitness, a.rmse_m


def _result(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D, tolerance: float,
            method: str) -> Alignment:
    """Score ``tf`` on the map against the truth tree."""
    fitness, rmse = _score_tree(map_xy, tree, tf, tolerance)
    return Alignment(tf, fitness, rmse, tolerance, method)


def _map_at_scale(map_xy: np.ndarray, tf: Similarity2D, voxel: float) -> np.ndarray:
    """The map (N, 2, map units) downsampled to ``voxel`` truth units under ``tf``'s scale."""
    return voxel_centroids(map_xy, voxel / tf.scale)


def align_similarity(map_xy: np.ndarray, truth_xy: np.ndarray, *,
                     init: Similarity2D | None = None, refine: bool = True,
                     tolerance: float = 0.2, voxel: float = 0.05,
                     resolution: float | None = None, top_k: int = 6, finalists: int = 3,
                     scale_range: tuple[float, float] = (0.2, 5.0)) -> Alignment:
    """Align a map of unknown unit to the truth: scale, rotation and translation, with no
    initial guess needed; never fails on a bad match.

    map_xy: (N, 2) in the map's own unit, map frame; truth_xy: (M, 2) truth units (metres),
    truth frame. Every length parameter is in truth units: ``tolerance`` and ``voxel`` as in
    :func:`align`; the map is downsampled to ``voxel`` truth units at the current scale.
    resolution: cell of the global search (default: the truth's radius / 20, see
    :func:`~pcmapq.align.coarse.similarity_search`), which also sets the ICP schedule
    (:func:`~pcmapq.align.similarity_icp.similarity_schedule`). The ``top_k`` candidates of the search over scale, yaw and
    position are refined by a first scaled ICP stage, the best ``finalists`` by fitness through
    the others and a point-to-line stage with scale (pairs within ``tolerance``); the final pose
    with the highest fitness wins. init: a starting similarity (its scale kept), skips the
    search. fitness and rmse_m are in the truth frame, as in :func:`align`.
    """
    map_xy = np.asarray(map_xy, dtype=np.float64).reshape(-1, 2)
    truth_ds = voxel_centroids(truth_xy, voxel)
    start = Similarity2D() if init is None else init
    if len(map_xy) == 0 or len(truth_ds) < 2:  # the truth must have a size
        return Alignment(start, 0.0, 0.0, tolerance, "none")
    tree = cKDTree(truth_ds)
    if not refine:
        return _result(_map_at_scale(map_xy, start, voxel), tree, start, tolerance,
                       "none" if init is None else "init")
    resolution = similarity_resolution(truth_ds) if resolution is None else resolution
    search = None
    if init is None:
        search = similarity_search(map_xy, truth_ds, scale_range=scale_range,
                                   resolution=resolution, top_k=top_k)
        starts, method = [c.transform for c in search.candidates], "similarity+icp"
    else:
        starts, method = [init], "init+icp"
    first, *rest = similarity_schedule(resolution, tolerance, voxel)
    rough, fine = SimilarityTarget(truth_ds, (first,)), SimilarityTarget(truth_ds, tuple(rest))
    firsts = [_scaled_result(map_xy, tree, refine_similarity(map_xy, rough, s), tolerance, voxel)
              for s in starts]
    finals = []
    for r in sorted(firsts, key=_rank)[:finalists]:
        tf = refine_similarity(map_xy, fine, r.transform)
        tf = refine_point_to_line(_map_at_scale(map_xy, tf, voxel), truth_ds, tf, tolerance,
                                  with_scale=True)
        finals.append(_scaled_result(map_xy, tree, tf, tolerance, voxel))
    best = min(finals, key=_rank)
    distinct = None if search is None else distinctiveness(search, best.transform)
    return Alignment(best.transform, best.fitness, best.rmse_m, tolerance, method, distinct)


def _scaled_result(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D, tolerance: float,
                   voxel: float) -> Alignment:
    """Score ``tf`` on the map (map units) downsampled to ``voxel`` truth units at its scale."""
    return _result(_map_at_scale(map_xy, tf, voxel), tree, tf, tolerance, "")
