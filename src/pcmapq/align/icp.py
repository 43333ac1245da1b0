"""Local 2D refinement: Open3D point-to-point ICP on points embedded at z = 0, projected back to
SE(2), then a final 2D point-to-line stage.

Point-to-point ICP has a wide basin but locks onto the lattice of two gridded clouds (a map equal
to its truth stopped 6 cm off); point-to-line lets points slide along walls and converges
exactly, so it finishes every refinement."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.transform import Similarity2D
from pcmapq.voxels import voxel_centroids

if TYPE_CHECKING:
    import open3d as o3d

#: ICP stages: (max correspondence distance, voxel size), metres. Both shrink stage by stage.
DEFAULT_SCHEDULE: tuple[tuple[float, float], ...] = ((1.0, 0.2), (0.5, 0.1), (0.2, 0.05))


def _cloud(xy: np.ndarray) -> o3d.geometry.PointCloud:
    """Points (N, 2, metres) as an Open3D cloud at z = 0."""
    import open3d as o3d  # heavy: loaded when ICP runs
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))


def _matrix4(tf: Similarity2D) -> np.ndarray:
    """The planar rigid part of ``tf`` as a 4x4 matrix (scale dropped)."""
    c, s = np.cos(tf.yaw), np.sin(tf.yaw)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:2, 3] = [tf.tx, tf.ty]
    return m


def _to_se2(m: np.ndarray) -> Similarity2D:
    """Project a 4x4 rigid transform to SE(2): yaw from R[:2, :2], t from [:2, 3]."""
    yaw = float(np.arctan2(m[1, 0] - m[0, 1], m[0, 0] + m[1, 1]))
    return Similarity2D(float(m[0, 3]), float(m[1, 3]), yaw)


class IcpTarget:
    """The truth cloud prepared once for every stage of a schedule, so many starts can share it."""

    def __init__(self, truth_xy: np.ndarray,
                 schedule: tuple[tuple[float, float], ...] = DEFAULT_SCHEDULE) -> None:
        """truth_xy: (N, 2) metres, truth frame; schedule: (max distance, voxel) pairs, metres."""
        self.schedule = schedule
        self.clouds = [_cloud(voxel_centroids(truth_xy, voxel)) for _, voxel in schedule]


def refine(map_xy: np.ndarray, target: IcpTarget, init: Similarity2D,
           max_iterations: int = 30) -> Similarity2D:
    """Point-to-point ICP of the map (N, 2, metres, map frame) onto the truth from ``init``.

    Runs the target's schedule of shrinking correspondence distances and voxel sizes, projecting
    to SE(2) after every stage. Returns the map -> truth transform (scale 1).
    """
    import open3d as o3d  # heavy: loaded when ICP runs

    tf = Similarity2D(init.tx, init.ty, init.yaw)
    criteria = o3d.pipelines.registration.ICPConvergenceCriteria(
        relative_fitness=1e-6, relative_rmse=1e-6, max_iteration=max_iterations)
    method = o3d.pipelines.registration.TransformationEstimationPointToPoint()
    for (max_dist, voxel), truth in zip(target.schedule, target.clouds, strict=True):
        source = _cloud(voxel_centroids(map_xy, voxel))
        result = o3d.pipelines.registration.registration_icp(
            source, truth, max_dist, _matrix4(tf), method, criteria)
        tf = _to_se2(np.asarray(result.transformation))
    return tf


def line_normals(xy: np.ndarray, neighbours: int = 8) -> np.ndarray:
    """Unit normal (N, 2) of the local line through each point (N, 2, metres): the direction of
    least spread of its nearest neighbours (PCA)."""
    _, idx = cKDTree(xy).query(xy, k=min(neighbours, len(xy)))
    near = xy[idx] - xy[idx].mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", near, near))
    return vectors[:, :, 0]


def refine_point_to_line(map_xy: np.ndarray, truth_xy: np.ndarray, init: Similarity2D,
                         max_distance: float = 0.2, iterations: int = 30,
                         with_scale: bool = False) -> Similarity2D:
    """2D point-to-line ICP (Gauss-Newton with Tukey weights) of the map (N, 2, metres, map
    frame) onto the truth (M, 2, metres, truth frame), from ``init``; pairs farther apart than
    ``max_distance`` metres are ignored. Returns the map -> truth transform: scale 1, or with
    ``with_scale`` the scale refined too (the map then in any unit, starting at ``init``'s)."""
    if len(truth_xy) < 3:
        return init
    normals, tree = line_normals(truth_xy), cKDTree(truth_xy)
    tf = init if with_scale else Similarity2D(init.tx, init.ty, init.yaw)
    for _ in range(iterations):
        p = tf.apply(map_xy)
        dist, j = tree.query(p, distance_upper_bound=max_distance)
        ok = np.isfinite(dist)
        if ok.sum() < 3:
            break
        p, n = p[ok], normals[j[ok]]
        r = np.einsum("ni,ni->n", p - truth_xy[j[ok]], n)
        # residual change for a step (dx, dy, dyaw[, ds]) about the origin:
        # n . (d + dyaw * perp(p) [+ ds * p])
        jac = np.column_stack([n[:, 0], n[:, 1], n[:, 1] * p[:, 0] - n[:, 0] * p[:, 1]])
        if with_scale:
            jac = np.column_stack([jac, np.einsum("ni,ni->n", n, p)])
        scale = max(1.4826 * float(np.median(np.abs(r))), 1e-3)
        w = np.clip(1.0 - (r / (4.685 * scale)) ** 2, 0.0, None) ** 2
        step = np.linalg.lstsq(jac.T @ (jac * w[:, None]), -jac.T @ (w * r), rcond=None)[0]
        if with_scale:
            update = Similarity2D(*step[:3], 1.0 + step[3])
            tf = Similarity2D.from_matrix(update.matrix @ tf.matrix)
        else:
            tf = Similarity2D.from_matrix(Similarity2D(*step).matrix @ tf.matrix)
            tf = Similarity2D(tf.tx, tf.ty, tf.yaw)  # keep scale exactly 1
        if np.abs(step[:2]).max() < 1e-6 and np.abs(step[2:]).max() < 1e-7:
            break
    return tf


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


class SimilarityTarget:
    """The truth prepared once for every stage of a scaled ICP schedule: per stage, the truth
    voxel-downsampled and its KD-tree."""

    def __init__(self, truth_xy: np.ndarray, schedule: tuple[tuple[float, float], ...]) -> None:
        """truth_xy: (N, 2) truth units; schedule: (max distance, voxel) pairs, truth units."""
        self.schedule = schedule
        self.points = [voxel_centroids(truth_xy, voxel) for _, voxel in schedule]
        self.trees = [cKDTree(points) for points in self.points]


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
