"""Global 3D registration with no initial guess: FPFH features matched, then RANSAC (Open3D).

Frames: the transform takes source points to the target frame, ``p_target = T @ p_source``;
metres. Both clouds come downsampled at the working ``voxel``.

Normals from 2 ``voxel`` neighbourhoods (at most 30 points); FPFH from 5 ``voxel`` (at most 100
points), computed only at the keypoints (:func:`keypoints`); Open3D's mutual nearest neighbours
in feature space (:func:`feature_matches`); Open3D's RANSAC on those matches: 3 per hypothesis,
edge-length and distance checkers, inliers within 1.5 ``voxel``, each hypothesis that passes
the checkers scored on the source's keypoints (an even sample of it: a fiftieth of a 20-scan
KITTI map, scored in a sixteenth of the whole map's time; after ICP a well-posed pair has the
same pose either way, a bent map another pose that fits it about as well). RANSAC is seeded
and held to one thread: its threads draw from one shared generator, so their interleaving would
pick the hypotheses.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import open3d as o3d

from pcmapq.core.errors import EvaluationError
from pcmapq.core.voxels import voxel_keys

__all__ = ["feature_matches", "global_registration", "keypoints"]

reg = o3d.pipelines.registration

#: RANSAC budget: hypotheses, and the confidence at which it stops early.
RANSAC_ITERATIONS = 100_000
RANSAC_CONFIDENCE = 0.999
#: Points whose features are matched, per cloud, at most.
MAX_KEYPOINTS = 8_000


def global_registration(source: np.ndarray, target: np.ndarray, voxel: float) -> np.ndarray:
    """4x4 source -> target transform of source (N, 3) onto target (M, 3), both downsampled at
    ``voxel`` metres, from FPFH matches and seeded RANSAC. Deterministic."""
    src, tgt = _cloud(source, voxel), _cloud(target, voxel)
    src_keys, tgt_keys = keypoints(source, 2.0 * voxel), keypoints(target, 2.0 * voxel)
    pairs = feature_matches(_fpfh(src, src_keys, voxel), _fpfh(tgt, tgt_keys, voxel))
    if len(pairs) < 3:
        raise EvaluationError("too few feature matches to register the clouds")
    scored = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(source[src_keys]))
    matches = np.column_stack([pairs[:, 0], tgt_keys[pairs[:, 1]]]).astype(np.int32)
    distance = 1.5 * voxel
    with _one_thread():
        o3d.utility.random.seed(0)
        result = reg.registration_ransac_based_on_correspondence(
            scored, tgt, o3d.utility.Vector2iVector(matches), distance,
            reg.TransformationEstimationPointToPoint(False), 3,
            [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9),
             reg.CorrespondenceCheckerBasedOnDistance(distance)],
            reg.RANSACConvergenceCriteria(RANSAC_ITERATIONS, RANSAC_CONFIDENCE))
    return np.array(result.transformation, dtype=np.float64)


def keypoints(points: np.ndarray, cell: float) -> np.ndarray:
    """Indices of a spatially even subset of ``points`` (N, 3), at most ``MAX_KEYPOINTS``: the
    first point of each cell, the cell (metres) starting at ``cell`` and doubling until few
    enough. Sorted, deterministic."""
    # The first point of each cell by np.unique: deterministic, one pass per cell size.
    while True:
        _, first = np.unique(voxel_keys(points, cell), return_index=True)
        if len(first) <= MAX_KEYPOINTS:
            return np.sort(first)
        cell *= 2.0


def feature_matches(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Mutual nearest neighbours between descriptors (N, D) and (M, D), by Open3D: (K, 2) int32
    index pairs (source, target) in source order. Never falls back to one-way matches."""
    pairs = reg.correspondences_from_features(_feature(source), _feature(target),
                                              mutual_filter=True, mutual_consistency_ratio=0.0)
    return np.asarray(pairs, dtype=np.int32).reshape(-1, 2)


def _feature(descriptors: np.ndarray) -> o3d.pipelines.registration.Feature:
    """An Open3D feature of descriptors (N, D)."""
    feature = reg.Feature()
    feature.data = np.ascontiguousarray(descriptors.T, dtype=np.float64)
    return feature


def _fpfh(cloud: o3d.geometry.PointCloud, keys: np.ndarray, voxel: float) -> np.ndarray:
    """FPFH (K, 33) of the cloud's points ``keys`` (K,), from 5 ``voxel`` neighbourhoods."""
    search = o3d.geometry.KDTreeSearchParamHybrid(radius=5.0 * voxel, max_nn=100)
    return np.asarray(reg.compute_fpfh_feature(cloud, search, keys.tolist()).data).T


def _cloud(points: np.ndarray, voxel: float) -> o3d.geometry.PointCloud:
    """An Open3D cloud of ``points`` (N, 3) with normals from 2 ``voxel`` neighbourhoods."""
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2.0 * voxel, max_nn=30))
    return cloud


@contextmanager
def _one_thread() -> Iterator[None]:
    """Open3D held to one thread (a limit for the whole process), then the limit before."""
    before = o3d.utility.get_max_threads()
    o3d.utility.set_max_threads(1)
    try:
        yield
    finally:
        o3d.utility.set_max_threads(before)
