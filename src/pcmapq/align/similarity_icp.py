"""2D point-to-point ICP with scale, for a map of unknown unit: Umeyama's closed-form
similarity fitted to nearest-neighbour pairs, stage by stage."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import voxel_centroids


def fit_similarity(src: np.ndarray, dst: np.ndarray) -> Similarity2D:
    """Least-squares similarity taking points ``src`` (N, 2) onto their partners ``dst`` (N, 2):
    Umeyama's closed form in complex numbers, always a proper rotation."""
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    # c = sum(conj(a) b) / sum(|a|^2), a and b read as complex numbers x + iy
    re = float(np.einsum("ni,ni->", a, b))
    im = float(np.dot(a[:, 0], b[:, 1]) - np.dot(a[:, 1], b[:, 0]))
    norm = max(float(np.einsum("ni,ni->", a, a)), 1e-300)
    c, s = re / norm, im / norm
    t = md - np.array([[c, -s], [s, c]]) @ ms
    return Similarity2D(float(t[0]), float(t[1]), float(np.arctan2(s, c)), float(np.hypot(c, s)))


def similarity_schedule(resolution: float, tolerance: float,
                        voxel: float) -> tuple[tuple[float, float], ...]:
    """Scaled ICP stages, (max distance, voxel) in truth units: from twice the global search's
    cell ``resolution`` down to twice ``tolerance``, the voxel shrinking towards ``voxel`` (the
    point-to-line stage that follows uses ``voxel`` itself)."""
    return ((2 * resolution, max(voxel, resolution / 4)),
            (resolution / 2, max(voxel, resolution / 8)),
            (2 * tolerance, max(voxel, tolerance / 2)))


class SimilarityTarget:
    """The truth prepared once for every stage of a scaled ICP schedule: per stage, the truth
    voxel-downsampled and its KD-tree."""

    def __init__(self, truth_xy: np.ndarray, schedule: tuple[tuple[float, float], ...]) -> None:
        """truth_xy: (N, 2) truth units; schedule: (max distance, voxel) pairs, truth units."""
        self.schedule = schedule
        self.points = [voxel_centroids(truth_xy, voxel) for _, voxel in schedule]
        self.trees = [cKDTree(points) for points in self.points]


# Hand-written, not Open3D's TransformationEstimationPointToPoint(with_scaling=True): the same
# Umeyama fit, but Open3D's rule (fitness and RMSE changing by under 1e-6 in truth units) leaves
# slow scale drifts unconverged (their steps change both by less than that, the scale far off),
# where this one, a move under 1e-4 of the stage's distance, is free of the unit.
def refine_similarity(map_xy: np.ndarray, target: SimilarityTarget, init: Similarity2D,
                      max_iterations: int = 30) -> Similarity2D:
    """Point-to-point ICP with scale of the map (N, 2, map units) onto the truth from ``init``.

    Every stage of the target's schedule downsamples the map to its voxel size (converted to map
    units with the current scale), pairs each map point with its nearest truth point within the
    stage's distance (truth units) and fits the similarity in closed form, until it moves the
    map by less than 1e-4 of that distance. Returns the map -> truth similarity.
    """
    tf = init
    for (max_dist, voxel), truth, tree in zip(target.schedule, target.points, target.trees,
                                             strict=True):
        source = voxel_centroids(map_xy, voxel / tf.scale)
        for _ in range(max_iterations):
            moved = tf.apply(source)
            dist, j = tree.query(moved, distance_upper_bound=max_dist)
            ok = np.isfinite(dist)
            if ok.sum() < 3:
                break
            new = fit_similarity(source[ok], truth[j[ok]])
            shift = np.abs(new.apply(source) - moved).max()
            tf = new
            if shift < 1e-4 * max_dist:
                break
    return tf
