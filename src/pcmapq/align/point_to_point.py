"""Rigid 2D point-to-point ICP stages: Open3D's ICP on points embedded at z = 0, projected back
to SE(2) after every stage. Open3D is imported when ICP runs, not with this module.

Point-to-point ICP has a wide basin but locks onto the lattice of two gridded clouds (a map equal
to its truth stopped 6 cm off), so a point-to-line stage (:mod:`pcmapq.align.point_to_line`)
finishes every refinement."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import voxel_centroids

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
    """The truth cloud prepared once for every stage of a schedule, so many starts can share it:
    one downsampled cloud per distinct voxel of the schedule."""

    def __init__(self, truth_xy: np.ndarray,
                 schedule: tuple[tuple[float, float], ...] = DEFAULT_SCHEDULE,
                 clouds: dict[float, o3d.geometry.PointCloud] | None = None) -> None:
        """truth_xy: (N, 2) metres, truth frame; schedule: (max distance, voxel) pairs, metres;
        clouds: downsampled clouds of these points by voxel, shared with other targets (those
        missing are made and added)."""
        self.schedule = schedule
        clouds = {} if clouds is None else clouds
        for voxel in dict.fromkeys(voxel for _, voxel in schedule):
            if voxel not in clouds:
                clouds[voxel] = _cloud(voxel_centroids(truth_xy, voxel))
        self.clouds = [clouds[voxel] for _, voxel in schedule]


def refine_point_to_point(map_xy: np.ndarray, target: IcpTarget, init: Similarity2D,
                          max_iterations: int = 30, stages: slice = slice(None)) -> Similarity2D:
    """Point-to-point ICP of the map (N, 2, metres, map frame) onto the truth from ``init``.

    Runs the target's schedule (its ``stages`` part) of shrinking correspondence distances and
    voxel sizes, projecting to SE(2) after every stage. Returns the map -> truth transform
    (scale 1).
    """
    import open3d as o3d  # heavy: loaded when ICP runs

    tf = Similarity2D(init.tx, init.ty, init.yaw)
    criteria = o3d.pipelines.registration.ICPConvergenceCriteria(
        relative_fitness=1e-6, relative_rmse=1e-6, max_iteration=max_iterations)
    method = o3d.pipelines.registration.TransformationEstimationPointToPoint()
    for (max_dist, voxel), truth in zip(target.schedule[stages], target.clouds[stages],
                                        strict=True):
        source = _cloud(voxel_centroids(map_xy, voxel))
        result = o3d.pipelines.registration.registration_icp(
            source, truth, max_dist, _matrix4(tf), method, criteria)
        tf = _to_se2(np.asarray(result.transformation))
    return tf
