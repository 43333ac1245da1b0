"""A global map from a scan sequence and given poses (e.g. a reference map from ground truth).

``p_world = poses[k] @ calib @ p_sensor_k``: ``calib`` takes the scanner's frame to the frame the
poses describe (identity when None); metres. For KITTI see :mod:`pcmapq.mapping.poses`: either
``lidar_poses_from_camera(P, Tr)`` with ``calib=None`` (map in the first LiDAR frame, as
KISS-ICP's), or ``P`` with ``calib=Tr`` (map in the first camera frame).

The scans are used as read (no deskewing), cropped to ``[min_range, max_range]`` metres from the
scanner like KISS-ICP's input.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from pcmapq.errors import InputError
from pcmapq.mapping.scans import open_scans
from pcmapq.voxels import VoxelMap

__all__ = ["build_map_from_poses"]


def build_map_from_poses(source: str | Path, poses: np.ndarray, calib: np.ndarray | None = None,
                         *, max_scans: int | None = None, voxel: float = 0.1,
                         progress: Callable[[int, int], None] | None = None,
                         min_range: float = 0.0, max_range: float = 100.0,
                         topic: str | None = None) -> np.ndarray:
    """Accumulate scan k placed by ``poses[k] @ calib`` into one map.

    source: a scan folder, ROS bag or MCAP file. poses: (K, 4, 4), one per scan in order; the
    scans used are the first ``min(K, max_scans)``, and a sequence with fewer scans than that is
    an error. calib: 4x4 scanner -> pose frame, or None. voxel: output cell, metres.
    progress: ``progress(done, total)`` after each scan.

    Returns the map (N, 3) float64, metres, in the poses' world frame. Deterministic.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
        raise InputError(f"poses: expected K x 4 x 4, got shape {poses.shape}")
    limit = len(poses) if max_scans is None else min(len(poses), max_scans)
    scans = open_scans(source, max_scans=limit, topic=topic)
    if len(scans) < limit:
        raise InputError(f"{scans.path}: {len(scans)} scans for {limit} poses")
    mount = np.eye(4) if calib is None else np.asarray(calib, dtype=np.float64).reshape(4, 4)
    grid = VoxelMap(voxel)
    for index, (points, _) in enumerate(scans):
        ranges = np.linalg.norm(points, axis=1)
        points = points[(ranges >= min_range) & (ranges <= max_range)]
        place = poses[index] @ mount
        grid.add(points @ place[:3, :3].T + place[:3, 3])
        if progress is not None:
            progress(index + 1, limit)
    return grid.points()
